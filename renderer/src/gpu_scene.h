// A scene on the device: acceleration structures plus the shading buffers the raygens read.
#pragma once

#include "probecast/scene/scene.h"
#include "vk_acceleration.h"

namespace probecast::renderer {

struct GpuScene {
  SceneAccel accel;
  Buffer triangleMaterial;  // uint per triangle
  Buffer materials;         // PtMaterial[]
  Buffer lights;            // PtLight[]
  uint32_t lightCount = 0;
};

void uploadGpuScene(VulkanDevice& d, const scene::Scene& scene, GpuScene& out);  // geometry + shading
void uploadGpuShading(VulkanDevice& d, const scene::Scene& scene, GpuScene& out);  // materials, lights only
void destroyGpuScene(VulkanDevice& d, GpuScene& g);

}  // namespace probecast::renderer
