// The raster client's forward pass: one graphics pipeline, dynamic rendering, offscreen targets.
#include "probecast/renderer/raster_client.h"

#include <algorithm>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu_scene.h"
#include "probecast/renderer/glossy_sh.h"
#include "raster.frag.h"
#include "raster.vert.h"
#include "raster_shared.h"

namespace probecast::renderer {
void fillInactiveProbes(ProbeVolumeData& v) {
  const glm::uvec3 n = v.dims;
  const size_t count = static_cast<size_t>(n.x) * n.y * n.z;
  if (v.active.size() != count) return;
  std::vector<uint8_t> known(v.active);
  bool anyKnown = std::any_of(known.begin(), known.end(), [](uint8_t k) { return k != 0; });
  if (!anyKnown) return;
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<uint8_t> next = known;
    for (uint32_t z = 0; z < n.z; ++z)
      for (uint32_t y = 0; y < n.y; ++y)
        for (uint32_t x = 0; x < n.x; ++x) {
          const size_t i = (static_cast<size_t>(z) * n.y + y) * n.x + x;
          if (known[i]) continue;
          float sum[27] = {};
          int m = 0;
          const int dx[6] = {-1, 1, 0, 0, 0, 0}, dy[6] = {0, 0, -1, 1, 0, 0}, dz[6] = {0, 0, 0, 0, -1, 1};
          for (int k = 0; k < 6; ++k) {
            const int xx = static_cast<int>(x) + dx[k], yy = static_cast<int>(y) + dy[k], zz = static_cast<int>(z) + dz[k];
            if (xx < 0 || yy < 0 || zz < 0 || xx >= static_cast<int>(n.x) || yy >= static_cast<int>(n.y) ||
                zz >= static_cast<int>(n.z))
              continue;
            const size_t j = (static_cast<size_t>(zz) * n.y + yy) * n.x + xx;
            if (!known[j]) continue;
            for (int c = 0; c < 27; ++c) sum[c] += v.probes[j * 27 + c];
            ++m;
          }
          if (m == 0) continue;
          for (int c = 0; c < 27; ++c) v.probes[i * 27 + c] = sum[c] / static_cast<float>(m);
          next[i] = 1;
          changed = true;
        }
    known.swap(next);
  }
}

struct RasterRenderer::Impl {
  VulkanDevice* d = nullptr;
  uint32_t width = 0, height = 0;
  GpuScene gpu;
  Buffer vertexNormals, vertexUvs;
  GpuImage color, depth;
  GpuImage probeTextures[RS_PROBE_TEXTURES];
  GpuImage envBrdf;
  static constexpr int kEnvBrdfSize = 32;
  VkSampler sampler = VK_NULL_HANDLE;
  Buffer readback;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  shaders::RsPushConstants push{};
  uint32_t indexCount = 0;

  void writeDescriptors() {
    const Buffer* buffers[5] = {&gpu.triangleMaterial, &gpu.materials, &gpu.lights, &gpu.texels, &gpu.textures};
    VkDescriptorBufferInfo infos[5];
    VkWriteDescriptorSet writes[7];
    for (uint32_t b = 0; b < 5; ++b) {
      infos[b] = {buffers[b]->buffer, 0, VK_WHOLE_SIZE};
      writes[b] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[b].dstSet = set;
      writes[b].dstBinding = b;
      writes[b].descriptorCount = 1;
      writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[b].pBufferInfo = &infos[b];
    }
    VkDescriptorImageInfo images[RS_PROBE_TEXTURES];
    const VkDescriptorImageInfo envInfo{sampler, envBrdf.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    for (int t = 0; t < RS_PROBE_TEXTURES; ++t)
      images[t] = {sampler, probeTextures[t].view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    writes[5] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[5].dstSet = set;
    writes[5].dstBinding = RS_BINDING_PROBES;
    writes[5].descriptorCount = RS_PROBE_TEXTURES;
    writes[5].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    writes[5].pImageInfo = images;
    writes[6] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[6].dstSet = set;
    writes[6].dstBinding = RS_BINDING_ENV_BRDF;
    writes[6].descriptorCount = 1;
    writes[6].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    writes[6].pImageInfo = &envInfo;
    vkUpdateDescriptorSets(d->device, 7, writes, 0, nullptr);
  }

  void uploadVolume(const glm::uvec3 dims, const std::vector<float>& probes) {
    for (GpuImage& img : probeTextures) destroyImage(*d, img);
    const size_t count = static_cast<size_t>(dims.x) * dims.y * dims.z;
    Buffer staging = createBuffer(*d, count * 4 * sizeof(float) * RS_PROBE_TEXTURES, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    float* dst = static_cast<float*>(staging.mapped);
    for (int t = 0; t < RS_PROBE_TEXTURES; ++t)
      for (size_t p = 0; p < count; ++p)
        for (int c = 0; c < 4; ++c) {
          const int k = 4 * t + c;
          dst[(static_cast<size_t>(t) * count + p) * 4 + c] = k < 27 ? probes[p * 27 + k] : 0.0f;
        }
    for (GpuImage& img : probeTextures)
      img = createImage(*d, VK_FORMAT_R32G32B32A32_SFLOAT, {dims.x, dims.y, dims.z},
                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, true);
    submitAndWait(*d, [&](VkCommandBuffer cmd) {
      for (int t = 0; t < RS_PROBE_TEXTURES; ++t) {
        transitionImage(cmd, probeTextures[t], VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        VkBufferImageCopy region{};
        region.bufferOffset = static_cast<VkDeviceSize>(t) * count * 4 * sizeof(float);
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {dims.x, dims.y, dims.z};
        vkCmdCopyBufferToImage(cmd, staging.buffer, probeTextures[t].image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                               &region);
        transitionImage(cmd, probeTextures[t], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      }
    });
    destroyBuffer(*d, staging);
    writeDescriptors();
  }
};

RasterRenderer::RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height)
    : impl_(std::make_unique<Impl>()) {
  if (scene.triangleCount() == 0) throw std::invalid_argument("scene " + scene.name + " has no triangles");
  if (width == 0 || height == 0) throw std::invalid_argument("raster target needs a size");
  Impl& s = *impl_;
  s.d = &context.device();
  VulkanDevice& d = *s.d;
  s.width = width;
  s.height = height;
  uploadGpuScene(d, scene, s.gpu);
  s.indexCount = static_cast<uint32_t>(scene.indices.size());
  s.color = createImage(d, VK_FORMAT_R32G32B32A32_SFLOAT, {width, height, 1},
                        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  s.depth = createImage(d, VK_FORMAT_D32_SFLOAT, {width, height, 1}, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  s.readback = createBuffer(d, static_cast<VkDeviceSize>(width) * height * 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VK_CHECK(vkCreateSampler(d.device, &sci, nullptr, &s.sampler));

  VkDescriptorSetLayoutBinding bindings[RS_BINDING_COUNT];
  for (uint32_t b = 0; b < RS_BINDING_COUNT; ++b) {
    bindings[b] = {};
    bindings[b].binding = b;
    bindings[b].descriptorType = b == RS_BINDING_PROBES || b == RS_BINDING_ENV_BRDF
                                     ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
                                     : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = b == RS_BINDING_PROBES ? RS_PROBE_TEXTURES : 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = RS_BINDING_COUNT;
  lci.pBindings = bindings;
  VK_CHECK(vkCreateDescriptorSetLayout(d.device, &lci, nullptr, &s.setLayout));
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                            sizeof(shaders::RsPushConstants)};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &s.setLayout;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(d.device, &pli, nullptr, &s.layout));

  const VkShaderModule vs = createShaderModule(d, kRasterVert, sizeof kRasterVert),
                       fs = createShaderModule(d, kRasterFrag, sizeof kRasterFrag);
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vs;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fs;
  stages[1].pName = "main";
  const VkVertexInputBindingDescription vb[3] = {{0, 12, VK_VERTEX_INPUT_RATE_VERTEX},
                                                 {1, 12, VK_VERTEX_INPUT_RATE_VERTEX},
                                                 {2, 8, VK_VERTEX_INPUT_RATE_VERTEX}};
  const VkVertexInputAttributeDescription va[3] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                   {1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                   {2, 2, VK_FORMAT_R32G32_SFLOAT, 0}};
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = 3;
  vi.pVertexBindingDescriptions = vb;
  vi.vertexAttributeDescriptionCount = 3;
  vi.pVertexAttributeDescriptions = va;
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vps{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vps.viewportCount = 1;
  vps.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState cba{};
  cba.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &cba;
  const VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dys{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dys.dynamicStateCount = 2;
  dys.pDynamicStates = dyn;
  const VkFormat colorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  VkPipelineRenderingCreateInfo rci{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  rci.colorAttachmentCount = 1;
  rci.pColorAttachmentFormats = &colorFormat;
  rci.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
  VkGraphicsPipelineCreateInfo gci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gci.pNext = &rci;
  gci.stageCount = 2;
  gci.pStages = stages;
  gci.pVertexInputState = &vi;
  gci.pInputAssemblyState = &ia;
  gci.pViewportState = &vps;
  gci.pRasterizationState = &rs;
  gci.pMultisampleState = &ms;
  gci.pDepthStencilState = &ds;
  gci.pColorBlendState = &cb;
  gci.pDynamicState = &dys;
  gci.layout = s.layout;
  VK_CHECK(vkCreateGraphicsPipelines(d.device, VK_NULL_HANDLE, 1, &gci, nullptr, &s.pipeline));
  vkDestroyShaderModule(d.device, vs, nullptr);
  vkDestroyShaderModule(d.device, fs, nullptr);

  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 5},
                                   {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, RS_PROBE_TEXTURES + 1}};
  createSingleDescriptorSet(d, s.setLayout, sizes, 2, s.pool, s.set);
  // The environment BRDF table, computed at start-up (glossy_sh.h), and the lobe fit.
  {
    const int n = Impl::kEnvBrdfSize;
    const std::vector<float> table = envBrdfTable(n, 256);
    Buffer staging = createBuffer(d, table.size() * sizeof(float), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(staging.mapped, table.data(), table.size() * sizeof(float));
    s.envBrdf = createImage(d, VK_FORMAT_R32G32_SFLOAT, {static_cast<uint32_t>(n), static_cast<uint32_t>(n), 1},
                            VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    submitAndWait(d, [&](VkCommandBuffer cmd) {
      transitionImage(cmd, s.envBrdf, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {static_cast<uint32_t>(n), static_cast<uint32_t>(n), 1};
      vkCmdCopyBufferToImage(cmd, staging.buffer, s.envBrdf.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      transitionImage(cmd, s.envBrdf, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
    destroyBuffer(d, staging);
    const GgxLobeFit fit = ggxLobeFit();
    s.push.lobeBand1 = {static_cast<float>(fit.band1[0]), static_cast<float>(fit.band1[1]),
                        static_cast<float>(fit.band1[2]), static_cast<float>(fit.band1[3])};
    s.push.lobeBand2 = {static_cast<float>(fit.band2[0]), static_cast<float>(fit.band2[1]),
                        static_cast<float>(fit.band2[2]), static_cast<float>(fit.band2[3])};
  }
  // No volume yet: a 1³ black one keeps every descriptor valid.
  s.uploadVolume(glm::uvec3(1), std::vector<float>(27, 0.0f));
  s.push.lightCount = s.gpu.lightCount;
}

RasterRenderer::~RasterRenderer() {
  Impl& s = *impl_;
  VulkanDevice& d = *s.d;
  vkDeviceWaitIdle(d.device);
  for (GpuImage& img : s.probeTextures) destroyImage(d, img);
  destroyImage(d, s.envBrdf);
  destroyImage(d, s.color);
  destroyImage(d, s.depth);
  destroyBuffer(d, s.readback);
  destroyGpuScene(d, s.gpu);
  if (s.sampler) vkDestroySampler(d.device, s.sampler, nullptr);
  if (s.pool) vkDestroyDescriptorPool(d.device, s.pool, nullptr);
  if (s.pipeline) vkDestroyPipeline(d.device, s.pipeline, nullptr);
  if (s.layout) vkDestroyPipelineLayout(d.device, s.layout, nullptr);
  if (s.setLayout) vkDestroyDescriptorSetLayout(d.device, s.setLayout, nullptr);
}

void RasterRenderer::setProbes(const ProbeVolumeData& volume) {
  const size_t count = static_cast<size_t>(volume.dims.x) * volume.dims.y * volume.dims.z;
  if (count == 0 || volume.probes.size() != count * 27) throw std::invalid_argument("probe volume size mismatch");
  ProbeVolumeData filled = volume;
  fillInactiveProbes(filled);
  impl_->uploadVolume(volume.dims, filled.probes);
  impl_->push.volumeMin = {volume.min.x, volume.min.y, volume.min.z, 1.0f};
  impl_->push.volumeMax = {volume.max.x, volume.max.y, volume.max.z, 0.0f};
  impl_->push.volumeDims = {static_cast<float>(volume.dims.x), static_cast<float>(volume.dims.y),
                            static_cast<float>(volume.dims.z), 0.0f};
}

glm::mat4 RasterRenderer::viewProjection(const CameraView& c) const {
  const float aspect = static_cast<float>(impl_->width) / static_cast<float>(impl_->height);
  glm::mat4 proj = glm::perspectiveRH_ZO(c.yfov, aspect, 0.01f, 200.0f);
  proj[1][1] = -proj[1][1];  // Vulkan's y points down
  return proj * glm::lookAtRH(c.position, c.position + c.forward, c.up);
}

Image RasterRenderer::render(const glm::mat4& viewProj, const glm::vec3& eye) {
  Impl& s = *impl_;
  VulkanDevice& d = *s.d;
  std::memcpy(&s.push.viewProj, &viewProj[0][0], sizeof(float) * 16);
  s.push.eye = {eye.x, eye.y, eye.z, 1.0f};
  submitAndWait(d, [&](VkCommandBuffer cmd) {
    transitionImage(cmd, s.color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    transitionImage(cmd, s.depth, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    VkRenderingAttachmentInfo colorInfo{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    colorInfo.imageView = s.color.view;
    colorInfo.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    colorInfo.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    colorInfo.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingAttachmentInfo depthInfo{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depthInfo.imageView = s.depth.view;
    depthInfo.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depthInfo.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depthInfo.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    depthInfo.clearValue.depthStencil = {1.0f, 0};
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {s.width, s.height}};
    ri.layerCount = 1;
    ri.colorAttachmentCount = 1;
    ri.pColorAttachments = &colorInfo;
    ri.pDepthAttachment = &depthInfo;
    vkCmdBeginRendering(cmd, &ri);
    const VkViewport viewport{0, 0, static_cast<float>(s.width), static_cast<float>(s.height), 0, 1};
    const VkRect2D scissor{{0, 0}, {s.width, s.height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.layout, 0, 1, &s.set, 0, nullptr);
    vkCmdPushConstants(cmd, s.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof s.push,
                       &s.push);
    const VkBuffer vbufs[3] = {s.gpu.accel.positions.buffer, s.gpu.normals.buffer, s.gpu.texcoords.buffer};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    vkCmdBindVertexBuffers(cmd, 0, 3, vbufs, offsets);
    vkCmdBindIndexBuffer(cmd, s.gpu.accel.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cmd, s.indexCount, 1, 0, 0, 0);
    vkCmdEndRendering(cmd);
    transitionImage(cmd, s.color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {s.width, s.height, 1};
    vkCmdCopyImageToBuffer(cmd, s.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.readback.buffer, 1, &region);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
  });
  Image out;
  out.width = s.width;
  out.height = s.height;
  out.rgb.resize(static_cast<size_t>(s.width) * s.height * 3);
  const float* src = static_cast<const float*>(s.readback.mapped);
  for (size_t i = 0; i < static_cast<size_t>(s.width) * s.height; ++i)
    for (int c = 0; c < 3; ++c) out.rgb[i * 3 + c] = src[i * 4 + c];
  return out;
}

}  // namespace probecast::renderer
