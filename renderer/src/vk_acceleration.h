// Acceleration structures: one BLAS of a scene's (spatially sorted) triangles, one TLAS instance.
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
  AccelerationStructure blas;
  AccelerationStructure tlas;
  Buffer instances;
};

// Builds BLAS + TLAS. The scene's triangles should already be in spatial order (finalizeScene).
void buildSceneAccel(VulkanDevice& d, const scene::Scene& scene, SceneAccel& out);
void destroySceneAccel(VulkanDevice& d, SceneAccel& a);

}  // namespace probecast::renderer
