// Acceleration structures: a scene's (spatially sorted) triangles in two BLASes — the leading run
// that is opaque to rays (opaque geometry: no any-hit) and the rest (cut-outs and transmissive
// surfaces: any-hit decides) — one TLAS instance each, its custom index the BLAS's first triangle.
#pragma once

#include "probecast/scene/scene.h"
#include "vk_resources.h"

namespace probecast::renderer {

struct AccelerationStructure {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer storage;
  VkDeviceAddress address = 0;
};

struct SceneAccel {
  Buffer positions;  // float3 per vertex, also read by shaders
  Buffer indices;    // uint3 per triangle, also read by shaders
  AccelerationStructure blas;          // triangles [0, opaqueTriangles)
  AccelerationStructure blasNonOpaque;  // triangles [opaqueTriangles, count)
  AccelerationStructure tlas;
  uint32_t opaqueTriangles = 0;
  Buffer instances;
};

// Builds BLAS + TLAS. The scene's triangles should already be in spatial order (finalizeScene).
void buildSceneAccel(VulkanDevice& d, const scene::Scene& scene, SceneAccel& out);
void destroySceneAccel(VulkanDevice& d, SceneAccel& a);

}  // namespace probecast::renderer
