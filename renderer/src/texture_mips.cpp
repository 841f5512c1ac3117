#include "texture_mips.h"

#include <algorithm>
#include <stdexcept>

#include <stb_image_resize.h>

namespace probecast::renderer {
namespace {

void appendPacked(const uint8_t* rgba, size_t pixels, std::vector<uint32_t>& texels) {
  for (size_t i = 0; i < pixels; ++i)
    texels.push_back(static_cast<uint32_t>(rgba[i * 4]) | (static_cast<uint32_t>(rgba[i * 4 + 1]) << 8) |
                     (static_cast<uint32_t>(rgba[i * 4 + 2]) << 16) | (static_cast<uint32_t>(rgba[i * 4 + 3]) << 24));
}

// One level from the one above it: a box filter (each output pixel is the mean of the input
// pixels it covers), wrapping at the edges as the textures repeat.
void halve(const std::vector<uint8_t>& in, uint32_t w, uint32_t h, bool srgb, std::vector<uint8_t>& out, uint32_t ow,
           uint32_t oh) {
  out.assign(static_cast<size_t>(ow) * oh * 4, 0);
  const int ok = stbir_resize(in.data(), static_cast<int>(w), static_cast<int>(h), 0, out.data(), static_cast<int>(ow),
                              static_cast<int>(oh), 0, STBIR_TYPE_UINT8, 4, srgb ? 3 : STBIR_ALPHA_CHANNEL_NONE, 0,
                              STBIR_EDGE_WRAP, STBIR_EDGE_WRAP, STBIR_FILTER_BOX, STBIR_FILTER_BOX,
                              srgb ? STBIR_COLORSPACE_SRGB : STBIR_COLORSPACE_LINEAR, nullptr);
  if (!ok) throw std::runtime_error("texture mip levels: resizing failed (out of memory)");
}

}  // namespace

uint32_t mipLevelCount(uint32_t width, uint32_t height) {
  uint32_t levels = 1;
  for (uint32_t side = std::max(width, height); side > 1; side /= 2) ++levels;
  return levels;
}

uint32_t appendMipChain(const scene::Texture& t, bool srgb, std::vector<uint32_t>& texels) {
  const size_t pixels = static_cast<size_t>(t.width) * t.height;
  if (t.rgba.size() < pixels * 4) throw std::invalid_argument("texture mip levels: fewer bytes than width × height × 4");
  appendPacked(t.rgba.data(), pixels, texels);
  const uint32_t levels = mipLevelCount(t.width, t.height);
  std::vector<uint8_t> level(t.rgba.begin(), t.rgba.begin() + static_cast<std::ptrdiff_t>(pixels * 4)), next;
  uint32_t w = t.width, h = t.height;
  for (uint32_t k = 1; k < levels; ++k) {
    const uint32_t nw = std::max(1u, w / 2), nh = std::max(1u, h / 2);
    halve(level, w, h, srgb, next, nw, nh);
    appendPacked(next.data(), static_cast<size_t>(nw) * nh, texels);
    level.swap(next);
    w = nw, h = nh;
  }
  return levels;
}

std::vector<bool> colourTextures(const scene::Scene& s) {
  std::vector<bool> colour(s.textures.size(), false);
  for (const scene::Material& m : s.materials)
    for (int32_t index : {m.baseColorTexture, m.emissiveTexture})  // the rest (data, normals) are linear
      if (index >= 0 && static_cast<size_t>(index) < colour.size()) colour[static_cast<size_t>(index)] = true;
  return colour;
}

}  // namespace probecast::renderer
