// The probe tracing pass: ray-tracing pipeline, shader binding table, descriptors, dispatch.
#pragma once

#include "probe_trace_shared.h"
#include "vk_acceleration.h"

namespace probecast::renderer {

struct ProbeTracePass {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  Buffer sbt;
  VkStridedDeviceAddressRegionKHR raygen{}, miss{}, hit{}, callable{};
};

// Buffers bound at PT_BINDING_* (the TLAS comes from the scene).
struct ProbeTraceInputs {
  const SceneAccel* accel;
  const Buffer* triangleMaterial;
  const Buffer* materials;
  const Buffer* lights;
  const Buffer* directions;
  const Buffer* probes;
  const Buffer* partials;
};

void createProbeTracePass(VulkanDevice& d, ProbeTracePass& pass);
void destroyProbeTracePass(VulkanDevice& d, ProbeTracePass& pass);
// Binds the inputs and traces LANES × probeCount invocations; waits for completion.
void runProbeTracePass(VulkanDevice& d, ProbeTracePass& pass, const ProbeTraceInputs& in,
                       const shaders::PtPushConstants& push);

}  // namespace probecast::renderer
