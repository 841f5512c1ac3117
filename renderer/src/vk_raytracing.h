// Ray-tracing passes: a raygen of the caller's plus the shared closest-hit and miss shaders,
// the shader binding table, the scene descriptor set (PT_BINDING_*), and dispatch.
#pragma once

#include "probe_trace_shared.h"
#include "gpu_scene.h"

namespace probecast::renderer {

struct RayTracingPass {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  Buffer sbt;
  VkStridedDeviceAddressRegionKHR raygen{}, miss{}, hit{}, callable{};
  uint32_t pushBytes = 0;
};

// What is bound at PT_BINDING_*: the scene, and the pass's own buffers.
struct RayTracingInputs {
  const GpuScene* scene;
  const Buffer* directions;
  const Buffer* probes;
  const Buffer* partials;
};

void createRayTracingPass(VulkanDevice& d, const uint32_t* raygen, size_t raygenBytes, uint32_t pushBytes,
                         RayTracingPass& pass);
void destroyRayTracingPass(VulkanDevice& d, RayTracingPass& pass);
// Binds the inputs, pushes `push` (pass.pushBytes), traces width × height invocations, and waits.
void runRayTracingPass(VulkanDevice& d, RayTracingPass& pass, const RayTracingInputs& in, const void* push,
                       uint32_t width, uint32_t height);

}  // namespace probecast::renderer
