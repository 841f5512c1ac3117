#include "vk_raytracing.h"

#include <cstring>
#include <vector>

#include "probe_shadow.rahit.h"
#include "probe_shadow.rmiss.h"
#include "probe_trace.rahit.h"
#include "probe_trace.rchit.h"
#include "probe_trace.rmiss.h"

namespace probecast::renderer {
namespace {

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

}  // namespace

void createRayTracingPass(VulkanDevice& d, const uint32_t* raygen, size_t raygenBytes, uint32_t pushBytes,
                         RayTracingPass& pass) {
  pass.pushBytes = pushBytes;
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  for (uint32_t b = 0; b < PT_BINDING_COUNT; ++b) {
    VkDescriptorSetLayoutBinding binding{};
    binding.binding = b;
    binding.descriptorType = b == PT_BINDING_TLAS ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR
                                                  : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    binding.descriptorCount = 1;
    // Raygen shades; any-hit reads materials and texture coordinates for cut-outs and transmission.
    binding.stageFlags = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_ANY_HIT_BIT_KHR;
    bindings.push_back(binding);
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = static_cast<uint32_t>(bindings.size());
  lci.pBindings = bindings.data();
  VK_CHECK(vkCreateDescriptorSetLayout(d.device, &lci, nullptr, &pass.setLayout));

  pass.layout = createPipelineLayout(d, pass.setLayout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, pushBytes);

  // Stages: raygen, miss, shadow miss, closest hit, path any-hit, shadow any-hit. Groups: raygen |
  // miss, shadow miss | hit group PT_HIT_GROUP_CLOSEST (closest hit + path any-hit),
  // PT_HIT_GROUP_SHADOW (shadow any-hit). Any-hit runs only on non-opaque geometry.
  constexpr uint32_t kStages = 6, kGroups = 5;
  const VkShaderModule modules[kStages] = {
      createShaderModule(d, raygen, raygenBytes),
      createShaderModule(d, kProbeTraceRmiss, sizeof kProbeTraceRmiss),
      createShaderModule(d, kProbeShadowRmiss, sizeof kProbeShadowRmiss),
      createShaderModule(d, kProbeTraceRchit, sizeof kProbeTraceRchit),
      createShaderModule(d, kProbeTraceRahit, sizeof kProbeTraceRahit),
      createShaderModule(d, kProbeShadowRahit, sizeof kProbeShadowRahit),
  };
  const VkShaderStageFlagBits stageBits[kStages] = {
      VK_SHADER_STAGE_RAYGEN_BIT_KHR,      VK_SHADER_STAGE_MISS_BIT_KHR,    VK_SHADER_STAGE_MISS_BIT_KHR,
      VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, VK_SHADER_STAGE_ANY_HIT_BIT_KHR, VK_SHADER_STAGE_ANY_HIT_BIT_KHR};
  VkPipelineShaderStageCreateInfo stages[kStages];
  for (uint32_t i = 0; i < kStages; ++i) {
    stages[i] = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[i].stage = stageBits[i];
    stages[i].module = modules[i];
    stages[i].pName = "main";
  }
  const auto group = [](VkRayTracingShaderGroupTypeKHR type, uint32_t general, uint32_t closest, uint32_t any) {
    VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    g.type = type;
    g.generalShader = general;
    g.closestHitShader = closest;
    g.anyHitShader = any;
    g.intersectionShader = VK_SHADER_UNUSED_KHR;
    return g;
  };
  constexpr uint32_t kNone = VK_SHADER_UNUSED_KHR;
  constexpr auto kGeneral = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  constexpr auto kTriangles = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
  const VkRayTracingShaderGroupCreateInfoKHR groups[kGroups] = {
      group(kGeneral, 0, kNone, kNone), group(kGeneral, 1, kNone, kNone), group(kGeneral, 2, kNone, kNone),
      group(kTriangles, kNone, 3, 4), group(kTriangles, kNone, kNone, 5)};
  static_assert(PT_HIT_GROUP_CLOSEST == 0 && PT_HIT_GROUP_SHADOW == 1 && PT_MISS_CLOSEST == 0 && PT_MISS_SHADOW == 1);
  VkRayTracingPipelineCreateInfoKHR pci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  pci.stageCount = kStages;
  pci.pStages = stages;
  pci.groupCount = kGroups;
  pci.pGroups = groups;
  pci.maxPipelineRayRecursionDepth = 1;  // only raygen traces
  pci.layout = pass.layout;
  VK_CHECK(d.vkCreateRayTracingPipelinesKHR(d.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &pci, nullptr, &pass.pipeline));
  for (VkShaderModule m : modules) vkDestroyShaderModule(d.device, m, nullptr);

  // Shader binding table: raygen | miss, shadow miss | hit, shadow hit, each region base-aligned.
  const auto& rt = d.rtProperties;
  const VkDeviceSize handle = rt.shaderGroupHandleSize;
  const VkDeviceSize stride = alignUp(handle, rt.shaderGroupHandleAlignment);
  const VkDeviceSize base = rt.shaderGroupBaseAlignment;
  std::vector<uint8_t> handles(handle * kGroups);
  VK_CHECK(d.vkGetRayTracingShaderGroupHandlesKHR(d.device, pass.pipeline, 0, kGroups, handles.size(), handles.data()));
  const VkDeviceSize raygenAt = 0, missAt = alignUp(stride, base), hitAt = alignUp(missAt + 2 * stride, base);
  pass.sbt = createBuffer(d, hitAt + 2 * stride + base,
                          VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  const VkDeviceAddress start = alignUp(pass.sbt.address, base);
  uint8_t* mapped = static_cast<uint8_t*>(pass.sbt.mapped) + (start - pass.sbt.address);
  std::memcpy(mapped + raygenAt, handles.data(), handle);
  std::memcpy(mapped + missAt, handles.data() + handle, handle);
  std::memcpy(mapped + missAt + stride, handles.data() + 2 * handle, handle);
  std::memcpy(mapped + hitAt, handles.data() + 3 * handle, handle);
  std::memcpy(mapped + hitAt + stride, handles.data() + 4 * handle, handle);
  pass.raygen = {start + raygenAt, stride, stride};
  pass.miss = {start + missAt, stride, 2 * stride};
  pass.hit = {start + hitAt, stride, 2 * stride};

  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, PT_BINDING_COUNT - 1}};
  createSingleDescriptorSet(d, pass.setLayout, sizes, 2, pass.pool, pass.set);
}

void destroyRayTracingPass(VulkanDevice& d, RayTracingPass& pass) {
  destroyBuffer(d, pass.sbt);
  if (pass.pool) vkDestroyDescriptorPool(d.device, pass.pool, nullptr);
  if (pass.pipeline) vkDestroyPipeline(d.device, pass.pipeline, nullptr);
  if (pass.layout) vkDestroyPipelineLayout(d.device, pass.layout, nullptr);
  if (pass.setLayout) vkDestroyDescriptorSetLayout(d.device, pass.setLayout, nullptr);
  pass = RayTracingPass{};
}

void runRayTracingPass(VulkanDevice& d, RayTracingPass& pass, const RayTracingInputs& in, const void* push,
                       uint32_t width, uint32_t height) {
  VkWriteDescriptorSetAccelerationStructureKHR asWrite{
      VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asWrite.accelerationStructureCount = 1;
  asWrite.pAccelerationStructures = &in.scene->accel.tlas.handle;
  const GpuScene& g = *in.scene;
  const Buffer* buffers[PT_BINDING_COUNT] = {};
  buffers[PT_BINDING_POSITIONS] = &g.accel.positions;
  buffers[PT_BINDING_INDICES] = &g.accel.indices;
  buffers[PT_BINDING_TRIANGLE_MATERIAL] = &g.triangleMaterial;
  buffers[PT_BINDING_MATERIALS] = &g.materials;
  buffers[PT_BINDING_LIGHTS] = &g.lights;
  buffers[PT_BINDING_DIRECTIONS] = in.directions;
  buffers[PT_BINDING_PROBES] = in.probes;
  buffers[PT_BINDING_PARTIALS] = in.partials;
  buffers[PT_BINDING_EMITTERS] = &g.emitters;
  buffers[PT_BINDING_NORMALS] = &g.normals;
  buffers[PT_BINDING_TEXCOORDS] = &g.texcoords;
  buffers[PT_BINDING_TEXELS] = &g.texels;
  buffers[PT_BINDING_TEXTURES] = &g.textures;
  buffers[PT_BINDING_ENVIRONMENT] = &g.environment;
  buffers[PT_BINDING_ENV_DATA] = &g.environmentData;
  VkDescriptorBufferInfo infos[PT_BINDING_COUNT];
  VkWriteDescriptorSet writes[PT_BINDING_COUNT];
  for (uint32_t b = 0; b < PT_BINDING_COUNT; ++b) {
    writes[b] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = pass.set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    if (b == PT_BINDING_TLAS) {
      writes[b].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
      writes[b].pNext = &asWrite;
    } else {
      infos[b] = {buffers[b]->buffer, 0, VK_WHOLE_SIZE};
      writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[b].pBufferInfo = &infos[b];
    }
  }
  vkUpdateDescriptorSets(d.device, PT_BINDING_COUNT, writes, 0, nullptr);
  submitAndWait(d, [&](VkCommandBuffer cmd) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pass.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pass.layout, 0, 1, &pass.set, 0, nullptr);
    vkCmdPushConstants(cmd, pass.layout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, pass.pushBytes, push);
    d.vkCmdTraceRaysKHR(cmd, &pass.raygen, &pass.miss, &pass.hit, &pass.callable, width, height, 1);
    // Make the shader writes visible to the host reading mapped buffers.
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier,
                         0, nullptr, 0, nullptr);
  });
}

}  // namespace probecast::renderer
