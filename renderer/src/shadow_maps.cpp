#include "shadow_maps.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <glm/gtc/matrix_transform.hpp>

#include "probecast/renderer/view_sets.h"
#include "raster_shared.h"
#include "shadow.frag.h"
#include "shadow_transmit.frag.h"
#include "depth.vert.h"
#include "shadow.vert.h"
#include "vk_pipeline.h"

namespace probecast::renderer {

constexpr VkShaderStageFlags kShadowStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

namespace {

constexpr VkFormat kTransmitFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkClearColorValue kTransmitClear = {{1.0f, 1.0f, 1.0f, static_cast<float>(RS_TRANSMIT_CLEAR_DEPTH)}};

// The transmittance layers: full size for a scene with transmissive triangles, else one clear texel.
void createTransmitLayers(VulkanDevice& d, uint32_t layers, bool needed, ShadowMaps& maps) {
  const uint32_t n = needed ? maps.size : 1;
  if (maps.transmit.layers == layers && maps.transmit.extent.width == n) return;
  destroyImage(d, maps.transmit);
  maps.transmit = createImageArray(d, kTransmitFormat, {n, n}, layers,
                                   VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                       VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  submitAndWait(d, [&](VkCommandBuffer cmd) {
    transitionImage(cmd, maps.transmit, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
    vkCmdClearColorImage(cmd, maps.transmit.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &kTransmitClear, 1, &all);
    transitionImage(cmd, maps.transmit, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  });
}

// Cascade splits: a blend of logarithmic (even texel density in depth) and uniform (not all
// texels spent next to a small near plane) splits.
constexpr float kLogSplitWeight = 0.75f;

// Corner k (bits: x, y, z at the maximum) of the scene's bounds.
glm::vec3 sceneCorner(const ShadowMaps& maps, int k) {
  return {(k & 1 ? maps.sceneMax : maps.sceneMin).x, (k & 2 ? maps.sceneMax : maps.sceneMin).y,
          (k & 4 ? maps.sceneMax : maps.sceneMin).z};
}

// An orthographic layer looking along `dir` over a square of half-size `radius` around `center`,
// whose light-space x, y snap to whole texels (the layer then moves by whole texels only, so
// shadow edges do not shimmer as the views move), deep enough for every caster of the scene.
glm::mat4 cascadeLayer(glm::vec3 dir, glm::vec3 center, float radius, const ShadowMaps& maps) {
  const glm::vec3 up = std::abs(dir.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::mat4 view = glm::lookAtRH(glm::vec3(0.0f), dir, up);
  glm::vec3 c = glm::vec3(view * glm::vec4(center, 1.0f));
  const float texel = 2.0f * radius / static_cast<float>(maps.size);
  c.x = std::floor(c.x / texel) * texel;
  c.y = std::floor(c.y / texel) * texel;
  float zmin = INFINITY, zmax = -INFINITY;  // light-space z of the scene's corners (the view looks down −z)
  for (int k = 0; k < 8; ++k) {
    const float z = (view * glm::vec4(sceneCorner(maps, k), 1.0f)).z;
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  const float margin = 1e-3f * (zmax - zmin) + 1e-3f;
  glm::mat4 ortho = glm::orthoRH_ZO(c.x - radius, c.x + radius, c.y - radius, c.y + radius, -zmax - margin,
                                    -zmin + margin);
  ortho[1][1] = -ortho[1][1];
  return ortho * view;
}

// Rounds a cascade's radius up to a step of 2^(1/8), so that small changes of the view set's depth
// range (its far end follows the scene) keep the texel size, and with it the snapping grid.
float quantizedRadius(float r) { return std::exp2(std::ceil(std::log2(std::max(r, 1e-4f)) * 8.0f) / 8.0f); }

void uploadLayers(const ShadowMaps& maps) {
  auto* dst = static_cast<shaders::RsShadowLayer*>(maps.layers.mapped);
  for (size_t k = 0; k < maps.matrices.size(); ++k) {
    std::memcpy(&dst[k].viewProj, &maps.matrices[k][0][0], sizeof dst[k].viewProj);
    dst[k].texel = {maps.texels[k].x, maps.texels[k].y, maps.texels[k].z, maps.texels[k].w};
  }
}

}  // namespace

void createDepthPipelines(VulkanDevice& d, VkPipelineLayout layout, bool depthBias, VkPipeline& opaque,
                          VkPipeline& cutout) {
  GraphicsPipelineDesc desc;
  desc.vertexCode = kDepthVert;  // positions only
  desc.vertexBytes = sizeof kDepthVert;
  desc.vertexStreams = 1;
  desc.depthBias = depthBias;
  desc.layout = layout;
  opaque = createGraphicsPipeline(d, desc);
  desc.vertexCode = kShadowVert;
  desc.vertexBytes = sizeof kShadowVert;
  desc.vertexStreams = 3;
  desc.fragmentCode = kShadowFrag;
  desc.fragmentBytes = sizeof kShadowFrag;
  desc.colorFormat = VK_FORMAT_UNDEFINED;  // depth only, with a fragment shader that may discard
  cutout = createGraphicsPipeline(d, desc);
}

void createShadowMaps(VulkanDevice& d, uint32_t size, uint32_t maxLayers, uint32_t cascades,
                      VkDescriptorSetLayout materials, ShadowMaps& out) {
  if (cascades < 1 || cascades > RS_MAX_CASCADES)
    throw std::invalid_argument("shadow cascades must be 1.." + std::to_string(RS_MAX_CASCADES));
  out.size = size;
  out.maxLayers = maxLayers;
  out.cascades = cascades;
  out.layout = createPipelineLayout(d, materials, kShadowStages, sizeof(shaders::RsShadowPush));
  createDepthPipelines(d, out.layout, true, out.pipeline, out.cutoutPipeline);
  GraphicsPipelineDesc desc;
  desc.vertexCode = kShadowVert;
  desc.vertexBytes = sizeof kShadowVert;
  desc.layout = out.layout;
  desc.fragmentCode = kShadowTransmitFrag;
  desc.fragmentBytes = sizeof kShadowTransmitFrag;
  desc.colorFormat = kTransmitFormat;
  desc.blend = ColorBlend::MultiplyMinAlpha;
  out.transmitPipeline = createGraphicsPipeline(d, desc);
}

void planShadowMaps(VulkanDevice& d, const scene::Scene& scene, ShadowMaps& maps) {
  const glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
  const float radius = std::max(0.5f * glm::length(scene.boundsMax - scene.boundsMin), 1e-3f);
  const float size = static_cast<float>(maps.size);
  std::vector<shaders::RsShadowLight> records;
  maps.matrices.clear();
  maps.suns.clear();
  maps.fittedViews.clear();
  maps.sceneMin = scene.boundsMin;
  maps.sceneMax = scene.boundsMax;
  maps.transmissiveFirst = scene::leadingTrianglesBelowClass(scene, 2);
  for (const scene::Light& l : scene.lights) {
    shaders::RsShadowLight r{RS_SHADOW_NONE, static_cast<uint32_t>(maps.matrices.size()), 0.0f, 1u};
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
    } else if (const uint32_t left = maps.maxLayers - static_cast<uint32_t>(maps.matrices.size()),
               cascades = std::min(maps.cascades, left);
               l.type == scene::LightType::Directional && cascades > 1) {
      // Placeholders over the whole scene until fitShadowCascades sees the view set.
      maps.suns.push_back({r.firstLayer, cascades, dir});
      for (uint32_t k = 0; k < cascades; ++k) maps.matrices.push_back(cascadeLayer(dir, center, radius, maps));
      r.kind = RS_SHADOW_ORTHO;
      r.texelScale = 2.0f * radius / size;
      r.cascades = cascades;
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
  if (records.empty()) records.push_back({RS_SHADOW_NONE, 0, 0.0f, 1u});
  uploadShadowPlan(d, records, maps.transmissiveFirst < scene.triangleCount(), maps);
}

void uploadShadowPlan(VulkanDevice& d, const std::vector<shaders::RsShadowLight>& records, bool transmissive,
                      ShadowMaps& maps) {
  maps.texels.assign(maps.matrices.size(), glm::vec4(0.0f));
  for (const shaders::RsShadowLight& r : records)
    if (r.kind == RS_SHADOW_ORTHO)
      for (uint32_t k = 0; k < r.cascades; ++k) maps.texels[r.firstLayer + k].x = r.texelScale;
    else if (r.kind != RS_SHADOW_NONE)
      for (uint32_t k = 0; k < (r.kind == RS_SHADOW_CUBE ? 6u : 1u); ++k) maps.texels[r.firstLayer + k].y = 1.0f;
  destroyBuffer(d, maps.lights);
  destroyBuffer(d, maps.layers);
  maps.lights =
      createBufferWithData(d, records.data(), records.size() * sizeof records[0], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  maps.layers = createBuffer(d, std::max<size_t>(1, maps.matrices.size()) * sizeof(shaders::RsShadowLayer),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  uploadLayers(maps);
  const uint32_t layers = std::max<uint32_t>(2, static_cast<uint32_t>(maps.matrices.size()));
  if (maps.depth.layers != layers) {
    destroyImage(d, maps.depth);
    maps.depth = createImageArray(d, VK_FORMAT_D32_SFLOAT, {maps.size, maps.size}, layers,
                                  VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    submitAndWait(d, [&](VkCommandBuffer cmd) {
      transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
  }
  createTransmitLayers(d, layers, transmissive, maps);
  maps.layerDirty.assign(maps.matrices.size(), 1);
}

uint32_t markLayersOfMovedGeometry(const std::vector<glm::vec3>& before, const std::vector<glm::vec3>& after,
                                   const std::vector<uint32_t>& indices, ShadowMaps& maps) {
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (before[v[0]] == after[v[0]] && before[v[1]] == after[v[1]] && before[v[2]] == after[v[2]]) continue;
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (uint32_t i : v) {
      lo = glm::min(lo, glm::min(before[i], after[i]));
      hi = glm::max(hi, glm::max(before[i], after[i]));
    }
    boxes.emplace_back(lo, hi);
  }
  uint32_t marked = 0;
  for (size_t k = 0; k < maps.matrices.size(); ++k) {
    if (maps.layerDirty[k]) continue;
    for (const auto& [lo, hi] : boxes) {
      // Outside the layer's clip volume when all eight corners are beyond one of its planes (x, y
      // in [-w, w], z ≤ w) or behind a perspective light (w ≤ 0); a box partly behind it counts as in.
      int outside[5] = {0, 0, 0, 0, 0};
      int behindCount = 0;
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        const glm::vec4 q = maps.matrices[k] * glm::vec4(p, 1.0f);
        behindCount += !(q.w > 0.0f);
        outside[0] += q.x < -q.w;
        outside[1] += q.x > q.w;
        outside[2] += q.y < -q.w;
        outside[3] += q.y > q.w;
        outside[4] += q.z > q.w;
      }
      const bool culled = behindCount == 8 || (behindCount == 0 && (outside[0] == 8 || outside[1] == 8 ||
                                                                     outside[2] == 8 || outside[3] == 8 || outside[4] == 8));
      if (!culled) {
        maps.layerDirty[k] = 1;
        ++marked;
        break;
      }
    }
  }
  return marked;
}

void fitShadowCascades(const std::vector<ViewInfo>& views, ShadowMaps& maps) {
  if (maps.suns.empty() || views.empty()) return;
  std::vector<float> key;
  for (const ViewInfo& v : views) {
    key.insert(key.end(), &v.viewProj[0][0], &v.viewProj[0][0] + 16);
    key.insert(key.end(), {v.eye.x, v.eye.y, v.eye.z});
  }
  if (key == maps.fittedViews) return;
  // Each view's frustum: the eye, its four near corners and its near-plane depth along the view
  // axis; the view set's depth range runs from the nearest near plane to the farthest point of
  // the scene in front of a view (no farther than a far plane).
  struct Frustum {
    glm::vec3 eye, corners[4];
    float nearDepth;
  };
  std::vector<Frustum> frusta;
  float nearest = INFINITY, farthest = 0.0f;
  for (const ViewInfo& v : views) {
    const glm::mat4 inv = glm::inverse(v.viewProj);
    auto unproject = [&](float x, float y, float z) {
      const glm::vec4 w = inv * glm::vec4(x, y, z, 1.0f);
      return glm::vec3(w) / w.w;
    };
    Frustum f{v.eye, {unproject(-1, -1, 0), unproject(1, -1, 0), unproject(1, 1, 0), unproject(-1, 1, 0)}, 0.0f};
    glm::vec3 axis = glm::cross(f.corners[1] - f.corners[0], f.corners[3] - f.corners[0]);
    if (glm::dot(axis, f.corners[0] - f.eye) < 0.0f) axis = -axis;
    axis = glm::normalize(axis);
    f.nearDepth = glm::dot(f.corners[0] - f.eye, axis);
    const glm::vec3 farCorner = unproject(-1, -1, 1);
    float farDepth = glm::dot(farCorner - f.eye, axis);
    if (!std::isfinite(farDepth) || farDepth <= f.nearDepth) farDepth = INFINITY;  // an infinite far plane
    float sceneDepth = 0.0f;
    for (int k = 0; k < 8; ++k) sceneDepth = std::max(sceneDepth, glm::dot(sceneCorner(maps, k) - f.eye, axis));
    // A view that is not a finite perspective frustum (NaN, or an eye off its apex) keeps the last fit.
    if (!(f.nearDepth > 0.0f) || !std::isfinite(f.nearDepth) || !std::isfinite(sceneDepth)) return;
    nearest = std::min(nearest, f.nearDepth);
    farthest = std::max(farthest, std::min(farDepth, sceneDepth));
    frusta.push_back(f);
  }
  maps.fittedViews = std::move(key);
  farthest = std::max(farthest, 1.01f * nearest);
  // Each cascade covers the slice [split k, split k+1] of every view's frustum: the sphere around
  // the slices' corners, so its size does not change as the views turn.
  const uint32_t cascades = maps.cascades;
  std::vector<float> splits(cascades + 1);
  for (uint32_t k = 0; k <= cascades; ++k) {
    const float t = static_cast<float>(k) / static_cast<float>(cascades);
    splits[k] = kLogSplitWeight * nearest * std::pow(farthest / nearest, t) +
                (1.0f - kLogSplitWeight) * (nearest + (farthest - nearest) * t);
  }
  const glm::vec3 sceneCenter = 0.5f * (maps.sceneMin + maps.sceneMax);
  const float sceneRadius = std::max(0.5f * glm::length(maps.sceneMax - maps.sceneMin), 1e-3f);
  for (const ShadowMaps::Sun& sun : maps.suns) {
    const uint32_t count = sun.count;
    for (uint32_t k = 0; k < count; ++k) {
      // The last layer of a light given fewer cascades than asked covers the rest of the range.
      const float d0 = splits[k], d1 = k + 1 == count ? splits[cascades] : splits[k + 1];
      std::vector<glm::vec3> points;
      for (const Frustum& f : frusta)
        for (const glm::vec3& c : f.corners)
          for (float depth : {d0, d1}) points.push_back(f.eye + (c - f.eye) * (depth / f.nearDepth));
      glm::vec3 center(0.0f);
      for (const glm::vec3& p : points) center += p;
      center /= static_cast<float>(points.size());
      float radius = 0.0f;
      for (const glm::vec3& p : points) radius = std::max(radius, glm::length(p - center));
      // A slice wider than the scene (the far one, mostly) needs no more than the scene's sphere.
      if (radius > sceneRadius) {
        center = sceneCenter;
        radius = sceneRadius;
      } else {
        radius = quantizedRadius(radius);
      }
      const uint32_t layer = sun.firstLayer + k;
      const glm::mat4 m = cascadeLayer(sun.direction, center, radius, maps);
      if (m == maps.matrices[layer]) continue;
      maps.matrices[layer] = m;
      maps.texels[layer].x = 2.0f * radius / static_cast<float>(maps.size);
      maps.layerDirty[layer] = 1;
    }
  }
  uploadLayers(maps);
}

void drawShadowMaps(VulkanDevice& d, const GpuScene& gpu, uint32_t indexCount, VkDescriptorSet materials,
                    ShadowMaps& maps) {
  if (std::find(maps.layerDirty.begin(), maps.layerDirty.end(), 1) == maps.layerDirty.end()) {
    maps.lastLayersDrawn = 0;
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const uint32_t n = maps.size;
  submitAndWait(d, [&](VkCommandBuffer cmd) {
    transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    const VkBuffer streams[3] = {gpu.accel.positions.buffer, gpu.normals.buffer, gpu.texcoords.buffer};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    const uint32_t triangles = indexCount / 3, opaque = std::min(gpu.accel.opaqueTriangles, triangles);
    const uint32_t transmissive = std::min(maps.transmissiveFirst, triangles);
    const bool transmit = transmissive < triangles;  // then `transmit` has full-size layers
    if (transmit)
      transitionImage(cmd, maps.transmit, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    for (size_t k = 0; k < maps.matrices.size(); ++k) {
      if (!maps.layerDirty[k]) continue;
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
      push.perspective = maps.texels[k].y != 0.0f ? 1u : 0u;
      // Opaque triangles first (the leading run, finalizeScene's order), then the cut-outs.
      const auto drawRun = [&](uint32_t first, uint32_t end, VkPipeline pipeline) {
        if (end <= first) return;
        push.primitiveBase = first;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        vkCmdPushConstants(cmd, maps.layout, kShadowStages, 0, sizeof push, &push);
        vkCmdDrawIndexed(cmd, 3 * (end - first), 1, 3 * first, 0, 0);
      };
      drawRun(0, opaque, maps.pipeline);
      drawRun(opaque, transmissive, maps.cutoutPipeline);
      vkCmdEndRendering(cmd);
      if (!transmit) continue;
      // The transmissive run over the finished depth: colour only.
      VkRenderingAttachmentInfo depthRead{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      depthRead.imageView = maps.depth.layerViews[k];
      depthRead.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
      depthRead.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
      depthRead.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      VkRenderingAttachmentInfo colour{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      colour.imageView = maps.transmit.layerViews[k];
      colour.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      colour.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      colour.clearValue.color = kTransmitClear;
      ri.colorAttachmentCount = 1;
      ri.pColorAttachments = &colour;
      ri.pDepthAttachment = &depthRead;
      vkCmdBeginRendering(cmd, &ri);
      setViewportScissor(cmd, n, n);
      drawRun(transmissive, triangles, maps.transmitPipeline);
      vkCmdEndRendering(cmd);
      ri.colorAttachmentCount = 0;
      ri.pColorAttachments = nullptr;
    }
    if (transmit)
      transitionImage(cmd, maps.transmit, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                      VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    transitionImage(cmd, maps.depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  });
  maps.lastLayersDrawn = static_cast<uint32_t>(std::count(maps.layerDirty.begin(), maps.layerDirty.end(), 1));
  std::fill(maps.layerDirty.begin(), maps.layerDirty.end(), 0);
  maps.lastDrawMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void destroyShadowMaps(VulkanDevice& d, ShadowMaps& maps) {
  destroyImage(d, maps.depth);
  destroyImage(d, maps.transmit);
  destroyBuffer(d, maps.lights);
  destroyBuffer(d, maps.layers);
  for (VkPipeline p : {maps.pipeline, maps.cutoutPipeline, maps.transmitPipeline})
    if (p) vkDestroyPipeline(d.device, p, nullptr);
  if (maps.layout) vkDestroyPipelineLayout(d.device, maps.layout, nullptr);
  maps = ShadowMaps{};
}

}  // namespace probecast::renderer
