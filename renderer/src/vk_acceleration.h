// Acceleration structures: a scene's (spatially sorted) triangles in one BLAS per run of the same
// kind — opaque to rays or not (opaque geometry needs no any-hit), still or moving with the scene
// clock (scene::movingTriangles) — one TLAS instance each, its custom index the run's first
// triangle. The moving runs are built to be refitted: when only their vertices move,
// refitSceneAccel updates them in place and rebuilds the TLAS over the few instances.
#pragma once

#include <vector>

#include "probecast/scene/scene.h"
#include "vk_resources.h"

namespace probecast::renderer {

struct AccelerationStructure {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer storage;
  VkDeviceAddress address = 0;
  VkDeviceSize updateScratch = 0;  // scratch bytes a refit needs (built to allow updates), else 0
};

struct BlasRun {
  uint32_t first = 0, count = 0;  // triangles
  bool opaque = true, moves = false;
  uint32_t refits = 0;  // since it was last built
  AccelerationStructure as;
};

struct SceneAccel {
  Buffer positions;  // float3 per vertex, also read by shaders (host-visible: refits write it)
  Buffer indices;    // uint3 per triangle, also read by shaders
  std::vector<BlasRun> blases;
  AccelerationStructure tlas;
  uint32_t opaqueTriangles = 0;
  uint32_t maxVertex = 0;
  Buffer instances;
  uint32_t refits = 0, rebuilds = 0;  // of moving runs, since the scene was built
};

// A moving run is built again, not refitted, after this many refits (refits loosen its boxes).
constexpr uint32_t kMaxRefits = 32;

// Builds the BLASes and the TLAS. The scene's triangles should already be in spatial order (finalizeScene).
void buildSceneAccel(VulkanDevice& d, const scene::Scene& scene, SceneAccel& out);
// The same triangles with moved vertices, all of them in moving runs: the positions are written,
// the moving runs refitted (or built again after kMaxRefits), the TLAS built again. False, with
// nothing changed, when a vertex outside the moving runs moved or the triangles differ: the
// caller builds anew.
bool refitSceneAccel(VulkanDevice& d, const scene::Scene& scene, const std::vector<glm::vec3>& before,
                     SceneAccel& a);
void destroySceneAccel(VulkanDevice& d, SceneAccel& a);
// Device bytes of the structures (BLAS and TLAS storage).
VkDeviceSize sceneAccelBytes(const SceneAccel& a);

}  // namespace probecast::renderer
