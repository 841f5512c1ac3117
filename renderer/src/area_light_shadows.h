// Client area lights on the device for the raster client: the RsAreaLight records, their triangle
// corners, and one shadow-map layer per light — a perspective view from the light's centroid along
// its normal, kAreaShadowFov wide, with the near plane just past the emitter's own triangles so a
// light never shadows itself. Points outside the frustum count as lit (a flat emitter lights
// little there). Drawn by drawShadowMaps like the punctual lights' maps: once per plan.
#pragma once

#include <vector>

#include "probecast/scene/area_lights.h"
#include "raster_shared.h"
#include "shadow_maps.h"

namespace probecast::renderer {

constexpr float kAreaShadowFovDegrees = 150.0f;

struct AreaLightBuffers {
  Buffer lights;   // RsAreaLight[] (at least one record, so the binding is never empty)
  Buffer corners;  // vec4[], 3 per triangle
  uint32_t count = 0;
};

// Uploads `set`'s lights into `out` (replacing what was there) and plans their shadow layers in
// `maps` (created by createShadowMaps): lights past maps.maxLayers stay unshadowed.
void planAreaLights(VulkanDevice& d, const scene::Scene& scene, const scene::AreaLightSet& set, ShadowMaps& maps,
                    AreaLightBuffers& out);
void destroyAreaLights(VulkanDevice& d, AreaLightBuffers& b);

}  // namespace probecast::renderer
