#include "shadow_maps.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>

#include "probecast/renderer/view_sets.h"
#include "raster_shared.h"
#include "shadow.frag.h"
#include "shadow.vert.h"
#include "vk_pipeline.h"

namespace probecast::renderer {

constexpr VkShaderStageFlags kShadowStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

void createShadowMaps(VulkanDevice& d, uint32_t size, uint32_t maxLayers, VkDescriptorSetLayout materials,
                      ShadowMaps& out) {
  out.size = size;
  out.maxLayers = maxLayers;
  out.layout = createPipelineLayout(d, materials, kShadowStages, sizeof(shaders::RsShadowPush));
  GraphicsPipelineDesc desc;
  desc.vertexCode = kShadowVert;
  desc.vertexBytes = sizeof kShadowVert;
  desc.depthBias = true;
  desc.layout = out.layout;
  out.pipeline = createGraphicsPipeline(d, desc);
  desc.fragmentCode = kShadowFrag;
  desc.fragmentBytes = sizeof kShadowFrag;
  desc.colorFormat = VK_FORMAT_UNDEFINED;  // depth only, with a fragment shader that may discard
  out.cutoutPipeline = createGraphicsPipeline(d, desc);
}

void planShadowMaps(VulkanDevice& d, const scene::Scene& scene, ShadowMaps& maps) {
  const glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
  const float radius = std::max(0.5f * glm::length(scene.boundsMax - scene.boundsMin), 1e-3f);
  const float size = static_cast<float>(maps.size);
  std::vector<shaders::RsShadowLight> records;
  maps.matrices.clear();
  for (const scene::Light& l : scene.lights) {
    shaders::RsShadowLight r{RS_SHADOW_NONE, static_cast<uint32_t>(maps.matrices.size()), 0.0f, 0.0f};
    const float zfar = l.range > 0.0f ? l.range : 2.0f * radius + glm::length(l.position - center);
    const float znear = std::max(1e-3f, 1e-4f * zfar);
    const glm::vec3 dir = glm::length(l.direction) > 0.0f ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
    const glm::vec3 up = std::abs(dir.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const bool wideSpot = l.type == scene::LightType::Spot && l.outerConeAngle > glm::radians(75.0f);
    if (l.type == scene::LightType::Point || wideSpot) {
      if (maps.matrices.size() + 6 > maps.maxLayers) {
        records.push_back(r);
        continue;
      }
      static const glm::vec3 kFaceDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      static const glm::vec3 kFaceUp[6] = {{0, 1, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};
      const glm::mat4 proj = vulkanPerspective(glm::radians(90.0f), 1.0f, znear, zfar);
      for (int f = 0; f < 6; ++f)
        maps.matrices.push_back(proj * glm::lookAtRH(l.position, l.position + kFaceDir[f], kFaceUp[f]));
      r.kind = RS_SHADOW_CUBE;
      r.texelScale = 2.0f / size;
    } else if (maps.matrices.size() + 1 > maps.maxLayers) {
      records.push_back(r);
      continue;
    } else if (l.type == scene::LightType::Spot) {
      const float fov = 2.0f * l.outerConeAngle + glm::radians(2.0f);
      maps.matrices.push_back(vulkanPerspective(fov, 1.0f, znear, zfar) *
                              glm::lookAtRH(l.position, l.position + dir, up));
      r.kind = RS_SHADOW_PERSPECTIVE;
      r.texelScale = 2.0f * std::tan(0.5f * fov) / size;
    } else {
      glm::mat4 ortho = glm::orthoRH_ZO(-radius, radius, -radius, radius, 0.0f, 2.0f * radius);
      ortho[1][1] = -ortho[1][1];
      maps.matrices.push_back(ortho * glm::lookAtRH(center - dir * radius, center, up));
      r.kind = RS_SHADOW_ORTHO;
      r.texelScale = 2.0f * radius / size;
    }
    records.push_back(r);
  }
  if (records.empty()) records.push_back({RS_SHADOW_NONE, 0, 0.0f, 0.0f});
  uploadShadowPlan(d, records, maps);
}

void uploadShadowPlan(VulkanDevice& d, const std::vector<shaders::RsShadowLight>& records, ShadowMaps& maps) {
  destroyBuffer(d, maps.lights);
  destroyBuffer(d, maps.layers);
  maps.lights =
      createBufferWithData(d, records.data(), records.size() * sizeof records[0], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  maps.layers = createBufferWithData(d, maps.matrices.data(), maps.matrices.size() * sizeof(glm::mat4),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const uint32_t layers = std::max<uint32_t>(2, static_cast<uint32_t>(maps.matrices.size()));
  if (maps.depth.layers != layers) {
    destroyImage(d, maps.depth);
    maps.depth = createImageArray(d, VK_FORMAT_D32_SFLOAT, {maps.size, maps.size}, layers,
                                  VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    submitAndWait(d, [&](VkCommandBuffer cmd) {
      transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
  }
  maps.dirty = true;
}

void drawShadowMaps(VulkanDevice& d, const GpuScene& gpu, uint32_t indexCount, VkDescriptorSet materials,
                    ShadowMaps& maps) {
  if (!maps.dirty) return;
  const auto t0 = std::chrono::steady_clock::now();
  const uint32_t n = maps.size;
  submitAndWait(d, [&](VkCommandBuffer cmd) {
    transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    const VkBuffer streams[3] = {gpu.accel.positions.buffer, gpu.normals.buffer, gpu.texcoords.buffer};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    const uint32_t opaque = std::min(gpu.accel.opaqueTriangles, indexCount / 3);
    for (size_t k = 0; k < maps.matrices.size(); ++k) {
      const VkRenderingAttachmentInfo depthInfo = clearedAttachment(
          maps.depth.layerViews[k], VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_STORE);
      VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
      ri.renderArea = {{0, 0}, {n, n}};
      ri.layerCount = 1;
      ri.pDepthAttachment = &depthInfo;
      vkCmdBeginRendering(cmd, &ri);
      setViewportScissor(cmd, n, n);
      vkCmdBindVertexBuffers(cmd, 0, 3, streams, offsets);
      vkCmdBindIndexBuffer(cmd, gpu.accel.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, maps.layout, 0, 1, &materials, 0, nullptr);
      shaders::RsShadowPush push{};
      std::memcpy(&push.viewProj, &maps.matrices[k][0][0], sizeof push.viewProj);
      // Opaque triangles first (the leading run, finalizeScene's order), then the rest.
      for (int part = 0; part < 2; ++part) {
        const uint32_t first = part == 0 ? 0 : opaque, count = part == 0 ? opaque : indexCount / 3 - opaque;
        if (count == 0) continue;
        push.primitiveBase = first;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, part == 0 ? maps.pipeline : maps.cutoutPipeline);
        vkCmdPushConstants(cmd, maps.layout, kShadowStages, 0, sizeof push, &push);
        vkCmdDrawIndexed(cmd, 3 * count, 1, 3 * first, 0, 0);
      }
      vkCmdEndRendering(cmd);
    }
    transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  });
  maps.dirty = false;
  maps.lastDrawMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void destroyShadowMaps(VulkanDevice& d, ShadowMaps& maps) {
  destroyImage(d, maps.depth);
  destroyBuffer(d, maps.lights);
  destroyBuffer(d, maps.layers);
  for (VkPipeline p : {maps.pipeline, maps.cutoutPipeline})
    if (p) vkDestroyPipeline(d.device, p, nullptr);
  if (maps.layout) vkDestroyPipelineLayout(d.device, maps.layout, nullptr);
  maps = ShadowMaps{};
}

}  // namespace probecast::renderer
