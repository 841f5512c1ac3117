#pragma once
// Mip chains of material textures, packed as the shaders read them (material.glsl): level 0 is the
// image, each next level halves each side (rounding down, at least 1) until 1 × 1. Colour textures
// (base colour, emission) are averaged as linear light and stored sRGB-encoded again, with colour
// weighted by alpha; data textures (metallic-roughness, occlusion) average their stored values.
// Each level is a box average over the pixels it covers, with repeat wrapping at the edges, so a
// level holds the mean a path tracer finds over the same footprint.

#include <cstdint>
#include <vector>

#include <probecast/scene/scene.h>

namespace probecast::renderer {

// Levels a w × h image has down to 1 × 1 (1 for an empty image).
uint32_t mipLevelCount(uint32_t width, uint32_t height);

// Appends every level of `t`, packed RGBA8 (R in the low byte) row by row, to `texels`; returns
// the number of levels. `srgb`: a colour texture (true) or a data texture (false).
uint32_t appendMipChain(const scene::Texture& t, bool srgb, std::vector<uint32_t>& texels);

// Which textures of the scene hold colour (read as sRGB by some material): the others are data.
std::vector<bool> colourTextures(const scene::Scene& s);

}  // namespace probecast::renderer
