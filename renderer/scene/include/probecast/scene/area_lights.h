// Client area lights: the emissive surfaces a viewer shades itself (exact Lambertian irradiance
// from each triangle, a GGX term, shadow maps from the emitter), so that probes need not carry
// their direct light. The rule (one function, used by the probe updater and the raster client, so
// they always agree): a material with constant (untextured) emission whose triangles together
// emit at least `minPowerFraction` of the scene's emitted power becomes client-lit, strongest
// first, while the count of lights stays within `maxLights` and of triangles within
// `maxTriangles`. Its triangles are split into connected pieces (shared vertex positions), one
// light each. Textured emitters always stay with the probes (their radiance is not constant).
// Power of a triangle = luminance of its radiance × area × π (a Lambertian emitter's flux).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/scene/scene.h"

namespace probecast::scene {

struct AreaLightOptions {
  bool enabled = false;            // off: every emitter reaches viewers through the probes
  float minPowerFraction = 0.05f;  // of the scene's total emitted power, per material
  uint32_t maxLights = 8;          // connected pieces over all chosen materials
  uint32_t maxTriangles = 64;      // over all lights (each costs every pixel an edge integral)
};

struct AreaLight {
  uint32_t material = 0;
  glm::vec3 radiance{0.0f};       // constant emitted radiance of its front faces
  std::vector<glm::vec3> corners; // 3 per triangle, counter-clockwise seen from the emitting side
  glm::vec3 centroid{0.0f};       // area-weighted
  glm::vec3 normal{0.0f, -1.0f, 0.0f};  // area-weighted mean of the triangles' normals (unit)
  float area = 0.0f;              // m²
  float power = 0.0f;             // luminance × area × π (W in our radiometric use)
};

struct AreaLightSet {
  std::vector<AreaLight> lights;
  std::vector<uint8_t> clientLitMaterial;  // per scene material: 1 when its emission is client-lit
  float totalEmittedPower = 0.0f;          // every emissive triangle of the scene, textured ones too
};

// The decision above. Empty (no light, every flag 0) when disabled or when nothing qualifies.
// Throws std::invalid_argument for a minimum share outside [0, 1] (NaN included).
AreaLightSet extractAreaLights(const Scene& scene, const AreaLightOptions& options);

}  // namespace probecast::scene
