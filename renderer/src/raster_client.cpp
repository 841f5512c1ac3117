// The raster client's forward pass: one graphics pipeline, dynamic rendering, offscreen targets.
#include "probecast/renderer/raster_client.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu_scene.h"
#include "probe_visibility.h"
#include "probecast/codec/priority.h"
#include "probecast/renderer/glossy_sh.h"
#include "raster.frag.h"
#include "raster.vert.h"
#include "area_light_shadows.h"
#include "raster_shared.h"
#include "shadow_maps.h"
#include "vk_pipeline.h"

namespace probecast::renderer {
namespace {

// One pass of the fill: every unknown probe with known neighbours takes their mean. Returns
// whether any probe became known.
bool fillStep(const uint32_t n[3], float* probes, std::vector<uint8_t>& known) {
  std::vector<uint8_t> next = known;
  bool changed = false;
  for (uint32_t z = 0; z < n[2]; ++z)
    for (uint32_t y = 0; y < n[1]; ++y)
      for (uint32_t x = 0; x < n[0]; ++x) {
        const size_t i = (static_cast<size_t>(z) * n[1] + y) * n[0] + x;
        if (known[i]) continue;
        float sum[27] = {};
        int m = 0;
        const int dx[6] = {-1, 1, 0, 0, 0, 0}, dy[6] = {0, 0, -1, 1, 0, 0}, dz[6] = {0, 0, 0, 0, -1, 1};
        for (int k = 0; k < 6; ++k) {
          const int xx = static_cast<int>(x) + dx[k], yy = static_cast<int>(y) + dy[k], zz = static_cast<int>(z) + dz[k];
          if (xx < 0 || yy < 0 || zz < 0 || xx >= static_cast<int>(n[0]) || yy >= static_cast<int>(n[1]) ||
              zz >= static_cast<int>(n[2]))
            continue;
          const size_t j = (static_cast<size_t>(zz) * n[1] + yy) * n[0] + xx;
          if (!known[j]) continue;
          for (int c = 0; c < 27; ++c) sum[c] += probes[j * 27 + c];
          ++m;
        }
        if (m == 0) continue;
        for (int c = 0; c < 27; ++c) probes[i * 27 + c] = sum[c] / static_cast<float>(m);
        next[i] = 1;
        changed = true;
      }
  known.swap(next);
  return changed;
}

// fillInactiveProbes on `probes` (27 floats per probe of grid `n`, modified in place).
void fillInactive(const uint32_t n[3], float* probes, const std::vector<uint8_t>& active) {
  std::vector<uint8_t> known(active);
  if (std::none_of(known.begin(), known.end(), [](uint8_t k) { return k != 0; })) return;
  while (fillStep(n, probes, known)) {
  }
}

}  // namespace

void fillInactiveProbes(ProbeVolume& v) {
  if (v.active.size() != v.count() || v.probes.size() != static_cast<size_t>(v.count()) * 27) return;
  fillInactive(v.grid.dims, v.probes.data(), v.active);
}

namespace {
using Clock = std::chrono::steady_clock;

// Sample counts the device offers for both raster targets (RGBA32F colour, D32 depth).
VkSampleCountFlags targetSampleCounts(const VulkanDevice& d) {
  VkImageFormatProperties color{}, depth{};
  if (vkGetPhysicalDeviceImageFormatProperties(d.physical, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_TYPE_2D,
                                               VK_IMAGE_TILING_OPTIMAL, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 0,
                                               &color) != VK_SUCCESS ||
      vkGetPhysicalDeviceImageFormatProperties(d.physical, VK_FORMAT_D32_SFLOAT, VK_IMAGE_TYPE_2D,
                                               VK_IMAGE_TILING_OPTIMAL, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0,
                                               &depth) != VK_SUCCESS)
    return VK_SAMPLE_COUNT_1_BIT;
  return color.sampleCounts & depth.sampleCounts;
}

// Where each probe was traced: its grid position plus its offset (ProbeVolume::offsets), xyz per
// probe. Throws std::invalid_argument for offsets that are neither empty nor 3 finite floats per
// probe, or that move a probe farther than the grid's size (+ 1 m): relocation stays inside a cell.
std::vector<float> probePositions(const ProbeVolume& v) {
  const size_t count = v.count();
  float reach = 1.0f;
  for (int a = 0; a < 3; ++a) reach = std::max(reach, v.grid.bounds.max[a] - v.grid.bounds.min[a] + 1.0f);
  if (!v.offsets.empty() && v.offsets.size() != count * 3)
    throw std::invalid_argument("probe offsets: " + std::to_string(v.offsets.size()) + " floats for " +
                                std::to_string(count) + " probes (want 3 per probe or none)");
  std::vector<float> out(count * 3);
  for (size_t i = 0; i < count; ++i) {
    v.grid.position(static_cast<uint32_t>(i), &out[i * 3]);
    if (v.offsets.empty()) continue;
    for (int c = 0; c < 3; ++c) {
      const float o = v.offsets[i * 3 + c];
      if (!std::isfinite(o) || std::abs(o) > reach)
        throw std::invalid_argument("probe offsets: probe " + std::to_string(i) + " moves " + std::to_string(o) +
                                    " m, not a finite offset within the grid");
      out[i * 3 + c] += o;
    }
  }
  return out;
}

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

VkDescriptorSetLayoutBinding layoutBinding(uint32_t binding, VkDescriptorType type, uint32_t count,
                                           VkShaderStageFlags stages) {
  VkDescriptorSetLayoutBinding b{};
  b.binding = binding;
  b.descriptorType = type;
  b.descriptorCount = count;
  b.stageFlags = stages;
  return b;
}

VkWriteDescriptorSet bufferWrite(VkDescriptorSet set, uint32_t binding, const VkDescriptorBufferInfo* info) {
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = info;
  return w;
}

VkWriteDescriptorSet imageWrite(VkDescriptorSet set, uint32_t binding, const VkDescriptorImageInfo* info,
                                uint32_t count) {
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set;
  w.dstBinding = binding;
  w.descriptorCount = count;
  w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  w.pImageInfo = info;
  return w;
}

// The same client area lights: the same emitters, corners and radiance (their shadow layers hold).
bool sameAreaLights(const scene::AreaLightSet& a, const scene::AreaLightSet& b) {
  if (a.lights.size() != b.lights.size() || a.clientLitMaterial != b.clientLitMaterial) return false;
  for (size_t k = 0; k < a.lights.size(); ++k)
    if (a.lights[k].material != b.lights[k].material || a.lights[k].corners != b.lights[k].corners ||
        a.lights[k].radiance != b.lights[k].radiance)
      return false;
  return true;
}

}  // namespace

struct RasterRenderer::Impl {
  static constexpr uint32_t kMaxViews = kMaxViewsPerSet;
  static constexpr int kEnvBrdfSize = 32;
  VulkanDevice* d = nullptr;
  RasterOptions options;
  RasterTimings timings;
  SurfaceRecord surfaces;  // as uploaded last
  size_t vertexCount = 0;
  std::vector<glm::vec3> positions;  // as uploaded last (setShading moves them)
  std::vector<glm::vec3> shadowBefore;  // the positions before the last move
  std::vector<scene::Light> shadedLights;     // of the last shadow plan
  std::vector<scene::Material> shadedMaterials;
  // The last visibility build's far distance, to draw probes again when the geometry moves.
  float visibilityFar = 0.0f;
  bool visibilityBuilt = false;
  uint32_t width = 0, height = 0, chunk = 1;  // of the targets: samplesPerSide × the images' size
  uint32_t drawWidth = 0, drawHeight = 0;     // the part of them drawn (setRenderScale; else all)
  float renderScale = 1.0f;
  GpuScene gpu;
  GpuImage color, depth;  // `chunk` layers each; with MSAA, depth is multisampled and color the resolve target
  GpuImage msColor;       // MSAA: the multisampled colour target
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  GpuImage probeTextures[RS_PROBE_TEXTURES];
  GpuImage envBrdf;
  ShadowMaps shadows;
  ProbeVisibility visibility;
  ShadowMaps areaShadows;  // one layer per client area light
  scene::AreaLightSet areaSet;
  AreaLightBuffers areaBuffers;
  VkSampler sampler = VK_NULL_HANDLE, shadowSampler = VK_NULL_HANDLE, depthSampler = VK_NULL_HANDLE;
  Buffer readback, views;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  std::map<uint32_t, VkPipeline> pipelines;  // by view mask (0: one view per pass)
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  shaders::RsPushConstants push{};
  uint32_t indexCount = 0;
  uint32_t drawnOpaque = 0;  // leading triangles drawn with depth writes (not transmissive)
  glm::vec3 sceneMin{0.0f}, sceneMax{0.0f};
  std::vector<glm::mat4> inverseViewProj;  // of the views being rendered, for the background

  // The environment's radiance along each pixel centre's ray, unprojected from the view's near and
  // far planes (off-axis views too), written as RGBA float with alpha 0 into `layer`: the colour
  // target starts from it, so transmissive surfaces in front of the sky tint it.
  void writeBackground(float* layer, const glm::mat4& inverse) const {
    for (uint32_t y = 0; y < drawHeight; ++y)
      for (uint32_t x = 0; x < drawWidth; ++x) {
        float* px = layer + (static_cast<size_t>(y) * drawWidth + x) * 4;
        px[0] = px[1] = px[2] = px[3] = 0.0f;
        const float nx = (static_cast<float>(x) + 0.5f) / static_cast<float>(drawWidth) * 2.0f - 1.0f;
        const float ny = (static_cast<float>(y) + 0.5f) / static_cast<float>(drawHeight) * 2.0f - 1.0f;
        const glm::vec4 nearPoint = inverse * glm::vec4(nx, ny, 0.0f, 1.0f);
        const glm::vec4 farPoint = inverse * glm::vec4(nx, ny, 1.0f, 1.0f);
        const glm::vec3 dir = glm::vec3(farPoint) / farPoint.w - glm::vec3(nearPoint) / nearPoint.w;
        const float len = glm::length(dir);
        if (!(len > 0.0f) || !std::isfinite(len)) continue;
        const glm::vec3 L = environmentRadiance(*options.environment, dir / len);
        for (int c = 0; c < 3; ++c) px[c] = L[c];
      }
  }
  // The client area lights of `scene` (the rule of area_lights.h), uploaded with their shadow plan.
  void planAreaLights(const scene::Scene& scene) {
    areaSet = scene::extractAreaLights(scene, options.areaLights);
    renderer::planAreaLights(*d, scene, areaSet, areaShadows, areaBuffers);
    push.areaLightCount = areaBuffers.count;
  }
  bool hasBackground() const { return options.environment && !options.environment->empty(); }

  void writeDescriptors() {
    constexpr uint32_t kBuffers = 12;
    const Buffer* buffers[kBuffers] = {&gpu.triangleMaterial, &gpu.materials, &gpu.lights, &gpu.texels,
                                       &gpu.textures, &views, &shadows.lights, &shadows.layers,
                                       &visibility.positions, &areaBuffers.lights, &areaBuffers.corners,
                                       &areaShadows.layers};
    const uint32_t bindings[kBuffers] = {RS_BINDING_TRIANGLE_MATERIAL, RS_BINDING_MATERIALS, RS_BINDING_LIGHTS,
                                         RS_BINDING_TEXELS, RS_BINDING_TEXTURES, RS_BINDING_VIEWS,
                                         RS_BINDING_SHADOW_LIGHTS, RS_BINDING_SHADOW_LAYERS,
                                         RS_BINDING_PROBE_POSITIONS, RS_BINDING_AREA_LIGHTS, RS_BINDING_AREA_CORNERS,
                                         RS_BINDING_AREA_SHADOW_LAYERS};
    VkDescriptorBufferInfo infos[kBuffers];
    VkWriteDescriptorSet writes[kBuffers + 7];
    for (uint32_t b = 0; b < kBuffers; ++b) {
      infos[b] = {buffers[b]->buffer, 0, VK_WHOLE_SIZE};
      writes[b] = bufferWrite(set, bindings[b], &infos[b]);
    }
    VkDescriptorImageInfo images[RS_PROBE_TEXTURES];
    for (int t = 0; t < RS_PROBE_TEXTURES; ++t)
      images[t] = {sampler, probeTextures[t].view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo envInfo{sampler, envBrdf.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo shadowInfo{shadowSampler, shadows.depth.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo momentsInfo{sampler, visibility.moments.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo transmitInfo{sampler, shadows.transmit.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo areaInfo{shadowSampler, areaShadows.depth.view,
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo areaDepthInfo{depthSampler, areaShadows.depth.view,
                                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    writes[kBuffers] = imageWrite(set, RS_BINDING_PROBES, images, RS_PROBE_TEXTURES);
    writes[kBuffers + 1] = imageWrite(set, RS_BINDING_ENV_BRDF, &envInfo, 1);
    writes[kBuffers + 2] = imageWrite(set, RS_BINDING_SHADOW_MAP, &shadowInfo, 1);
    writes[kBuffers + 3] = imageWrite(set, RS_BINDING_PROBE_MOMENTS, &momentsInfo, 1);
    writes[kBuffers + 4] = imageWrite(set, RS_BINDING_SHADOW_TRANSMIT, &transmitInfo, 1);
    writes[kBuffers + 5] = imageWrite(set, RS_BINDING_AREA_SHADOW_MAP, &areaInfo, 1);
    writes[kBuffers + 6] = imageWrite(set, RS_BINDING_AREA_SHADOW_DEPTH, &areaDepthInfo, 1);
    vkUpdateDescriptorSets(d->device, kBuffers + 7, writes, 0, nullptr);
  }

  // Coefficients premultiplied by a weight, the weight in the last texel's w: after trilinear
  // filtering, dividing by the filtered weight renormalises over active probes only. Inactive
  // probes weigh kInactiveWeight (their filled value only shows where no active probe is near).
  static constexpr float kInactiveWeight = 1e-3f;
  uint32_t volumeDims[3] = {0, 0, 0};  // size of the probe textures and of `staging`
  Buffer staging;                       // mapped; RS_PROBE_TEXTURES texels per probe, texture-major
  std::vector<float> filled;            // a volume with inactive probes, filled (capacity kept)

  // Probe textures and staging memory for a grid, kept across updates of the same size.
  // New storage is made before the old is freed: when creating it throws, the old textures,
  // descriptors and size stay as they were.
  void ensureVolumeStorage(const uint32_t dims[3]) {
    if (staging.buffer && std::equal(dims, dims + 3, volumeDims)) return;
    const size_t count = static_cast<size_t>(dims[0]) * dims[1] * dims[2];
    Buffer newStaging;
    GpuImage newTextures[RS_PROBE_TEXTURES];
    try {
      newStaging = createBuffer(*d, count * 4 * sizeof(float) * RS_PROBE_TEXTURES, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
      for (GpuImage& img : newTextures)
        img = createImage(*d, VK_FORMAT_R32G32B32A32_SFLOAT, {dims[0], dims[1], dims[2]},
                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, true);
    } catch (...) {
      for (GpuImage& img : newTextures) destroyImage(*d, img);
      destroyBuffer(*d, newStaging);
      throw;
    }
    for (int t = 0; t < RS_PROBE_TEXTURES; ++t) {
      destroyImage(*d, probeTextures[t]);
      probeTextures[t] = newTextures[t];
    }
    destroyBuffer(*d, staging);
    staging = newStaging;
    std::copy(dims, dims + 3, volumeDims);
    writeDescriptors();
  }

  // Writes the volume into the staging memory (straight from `v`, or from `filled` when some
  // probes are inactive) and copies it into the textures.
  void uploadVolume(const ProbeVolume& v) {
    ensureVolumeStorage(v.grid.dims);
    const size_t count = v.count();
    const float* probes = v.probes.data();
    if (std::any_of(v.active.begin(), v.active.end(), [](uint8_t a) { return a == 0; })) {
      filled.assign(v.probes.begin(), v.probes.end());
      fillInactive(v.grid.dims, filled.data(), v.active);
      probes = filled.data();
    }
    float* dst = static_cast<float*>(staging.mapped);
    for (size_t p = 0; p < count; ++p) {
      const float weight = v.active[p] ? 1.0f : kInactiveWeight;
      const float* src = probes + p * 27;
      for (int t = 0; t < RS_PROBE_TEXTURES; ++t)
        for (int c = 0; c < 4; ++c) {
          const int k = 4 * t + c;
          dst[(static_cast<size_t>(t) * count + p) * 4 + c] = k < 27 ? weight * src[k] : weight;
        }
    }
    submitAndWait(*d, [&](VkCommandBuffer cmd) {
      for (int t = 0; t < RS_PROBE_TEXTURES; ++t) {
        transitionImage(cmd, probeTextures[t], VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        VkBufferImageCopy region{};
        region.bufferOffset = static_cast<VkDeviceSize>(t) * count * 4 * sizeof(float);
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {v.grid.dims[0], v.grid.dims[1], v.grid.dims[2]};
        vkCmdCopyBufferToImage(cmd, staging.buffer, probeTextures[t].image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                               &region);
        transitionImage(cmd, probeTextures[t], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      }
    });
  }

  // Opaque and cut-out triangles (the leading run of finalizeScene's order) with depth writes,
  // then the transmissive ones twice: × T, then + their own light (raster.frag).
  void drawScene(VkCommandBuffer cmd, uint32_t viewMask) {
    const VkBuffer vbufs[3] = {gpu.accel.positions.buffer, gpu.normals.buffer, gpu.texcoords.buffer};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    vkCmdBindVertexBuffers(cmd, 0, 3, vbufs, offsets);
    vkCmdBindIndexBuffer(cmd, gpu.accel.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    const uint32_t triangles = indexCount / 3, opaque = std::min(drawnOpaque, triangles);
    const struct {
      uint32_t pass, first, count;
    } draws[3] = {{RS_PASS_OPAQUE, 0, opaque},
                  {RS_PASS_TRANSMIT, opaque, triangles - opaque},
                  {RS_PASS_REFLECT, opaque, triangles - opaque}};
    for (const auto& draw : draws) {
      if (draw.count == 0) continue;
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineFor(viewMask, draw.pass));
      push.pass = draw.pass;
      push.primitiveBase = draw.first;
      vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push, &push);
      vkCmdDrawIndexed(cmd, 3 * draw.count, 1, 3 * draw.first, 0, 0);
    }
  }

  VkPipeline pipelineFor(uint32_t viewMask, uint32_t pass) {
    const uint32_t key = viewMask | (pass << 16);
    auto it = pipelines.find(key);
    if (it == pipelines.end()) {
      GraphicsPipelineDesc desc;
      desc.vertexCode = kRasterVert;
      desc.vertexBytes = sizeof kRasterVert;
      desc.fragmentCode = kRasterFrag;
      desc.fragmentBytes = sizeof kRasterFrag;
      desc.viewMask = viewMask;
      desc.layout = layout;
      desc.samples = samples;
      desc.blend = pass == RS_PASS_OPAQUE ? ColorBlend::None
                                          : (pass == RS_PASS_TRANSMIT ? ColorBlend::Multiply : ColorBlend::Add);
      it = pipelines.emplace(key, createGraphicsPipeline(*d, desc)).first;
    }
    return it->second;
  }

  // Renders views [first, first + count) into layers 0..count-1 and reads them back.
  void renderChunk(uint32_t first, uint32_t count, std::vector<Image>& out) {
    const size_t pixels = static_cast<size_t>(drawWidth) * drawHeight;
    const bool msaa = samples != VK_SAMPLE_COUNT_1_BIT;
    // Without MSAA the target starts as the environment; with it, the environment goes behind the
    // resolved pixels afterwards, weighted by what their samples left uncovered (alpha).
    const bool background = hasBackground() && !msaa;
    if (background)
      for (uint32_t v = 0; v < count; ++v)
        writeBackground(static_cast<float*>(readback.mapped) + v * pixels * 4, inverseViewProj[first + v]);
    submitAndWait(*d, [&](VkCommandBuffer cmd) {
      if (msaa) {
        transitionImage(cmd, msColor, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        transitionImage(cmd, color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
      } else if (background) {  // the colour target starts as the environment (alpha 0: no surface)
        transitionImage(cmd, color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, count};
        region.imageExtent = {drawWidth, drawHeight, 1};
        vkCmdCopyBufferToImage(cmd, readback.buffer, color.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        transitionImage(cmd, color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
      } else {
        transitionImage(cmd, color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
      }
      transitionImage(cmd, depth, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
      const bool multiview = options.passes == ViewPasses::Multiview && count > 1;
      const uint32_t passes = multiview ? 1 : count;
      for (uint32_t p = 0; p < passes; ++p) {
        const VkImageView colorView = multiview || chunk == 1 ? color.view : color.layerViews[p];
        const VkImageView depthView = multiview || chunk == 1 ? depth.view : depth.layerViews[p];
        VkRenderingAttachmentInfo colorInfo =
            clearedAttachment(colorView, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_STORE);
        if (background) colorInfo.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
        if (msaa) {  // drawn into the samples, averaged into `color` at the end of the pass
          colorInfo.imageView = multiview || chunk == 1 ? msColor.view : msColor.layerViews[p];
          colorInfo.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
          colorInfo.resolveMode = VK_RESOLVE_MODE_AVERAGE_BIT;
          colorInfo.resolveImageView = colorView;
          colorInfo.resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        }
        const VkRenderingAttachmentInfo depthInfo =
            clearedAttachment(depthView, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_DONT_CARE);
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{0, 0}, {drawWidth, drawHeight}};
        ri.layerCount = 1;
        ri.viewMask = multiview ? (1u << count) - 1u : 0u;
        ri.colorAttachmentCount = 1;
        ri.pColorAttachments = &colorInfo;
        ri.pDepthAttachment = &depthInfo;
        vkCmdBeginRendering(cmd, &ri);
        setViewportScissor(cmd, drawWidth, drawHeight);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineFor(ri.viewMask, RS_PASS_OPAQUE));
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set, 0, nullptr);
        push.viewBase = first + p;
        drawScene(cmd, ri.viewMask);
        vkCmdEndRendering(cmd);
      }
      transitionImage(cmd, color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, count};
      region.imageExtent = {drawWidth, drawHeight, 1};
      vkCmdCopyImageToBuffer(cmd, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &region);
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr,
                           0, nullptr);
    });
    if (msaa && hasBackground()) {  // the environment behind what the samples left uncovered
      std::vector<float> env(pixels * 4);
      for (uint32_t v = 0; v < count; ++v) {
        writeBackground(env.data(), inverseViewProj[first + v]);
        float* layer = static_cast<float*>(readback.mapped) + v * pixels * 4;
        for (size_t i = 0; i < pixels; ++i) {
          const float uncovered = std::clamp(1.0f - layer[i * 4 + 3], 0.0f, 1.0f);
          for (size_t c = 0; c < 3; ++c) layer[i * 4 + c] += uncovered * env[i * 4 + c];
        }
      }
    }
    // Each image pixel is the mean of its samplesPerSide² target pixels (one: a plain copy).
    const float* src = static_cast<const float*>(readback.mapped);
    const uint32_t n = options.samplesPerSide;
    const float weight = 1.0f / static_cast<float>(n * n);
    for (uint32_t v = 0; v < count; ++v) {
      Image& img = out[first + v];
      img.width = drawWidth / n;
      img.height = drawHeight / n;
      img.rgb.assign(static_cast<size_t>(img.width) * img.height * 3, 0.0f);
      const float* layer = src + v * pixels * 4;
      for (uint32_t y = 0; y < drawHeight; ++y) {
        float* row = img.rgb.data() + static_cast<size_t>(y / n) * img.width * 3;
        const float* in = layer + static_cast<size_t>(y) * drawWidth * 4;
        for (uint32_t x = 0; x < drawWidth; ++x)
          for (uint32_t c = 0; c < 3; ++c) row[(x / n) * 3 + c] += weight * in[x * 4 + c];
      }
    }
  }
};

void checkRasterSize(uint32_t width, uint32_t height, const RasterOptions& options) {
  if (width == 0 || height == 0) throw std::invalid_argument("raster target needs a size");
  if (options.samplesPerSide < 1 || options.samplesPerSide > 16)
    throw std::invalid_argument("raster samples per pixel side must be 1..16");
  if (options.msaaSamples != 1 && options.msaaSamples != 2 && options.msaaSamples != 4 && options.msaaSamples != 8)
    throw std::invalid_argument("MSAA samples must be 1, 2, 4 or 8");
  if (options.anisotropy < 1 || options.anisotropy > 16)
    throw std::invalid_argument("texture anisotropy must be 1..16 taps");
  if (std::max(width, height) > 16384u / options.samplesPerSide)
    throw std::invalid_argument("a " + std::to_string(width) + "x" + std::to_string(height) + " view at " +
                                std::to_string(options.samplesPerSide) +
                                " samples per pixel side would render over 16384 pixels a side");
}

RasterRenderer::RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height,
                               const RasterOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (scene.triangleCount() == 0) throw std::invalid_argument("scene " + scene.name + " has no triangles");
  checkRasterSize(width, height, options);
  if (!(options.visibilityReach >= 0.0f && options.visibilityReach <= 1e6f))
    throw std::invalid_argument("visibility reach must be 0 (no limit) or a positive multiple of the rule, up to 1e6");
  if (options.shadowMapSize < 16 || options.shadowMapSize > 8192)
    throw std::invalid_argument("shadow map size must be 16..8192");
  if (options.shadowCascades < 1 || options.shadowCascades > RS_MAX_CASCADES)
    throw std::invalid_argument("shadow cascades must be 1.." + std::to_string(RS_MAX_CASCADES));
  Impl& s = *impl_;
  s.d = &context.device();
  VulkanDevice& d = *s.d;
  s.options = options;
  s.width = width * options.samplesPerSide;
  s.height = height * options.samplesPerSide;
  s.drawWidth = s.width;
  s.drawHeight = s.height;
  s.chunk = std::min<uint32_t>(8, d.maxMultiviewViewCount);
  s.sceneMin = scene.boundsMin;
  s.sceneMax = scene.boundsMax;
  uploadGpuScene(d, scene, s.gpu);
  s.surfaces.changedBy(scene);
  s.vertexCount = scene.positions.size();
  s.positions = scene.positions;
  s.indexCount = static_cast<uint32_t>(scene.indices.size());
  s.drawnOpaque = scene::leadingTrianglesBelowClass(scene, 2);
  s.samples = static_cast<VkSampleCountFlagBits>(options.msaaSamples);
  if (s.samples != VK_SAMPLE_COUNT_1_BIT) {
    const VkSampleCountFlags offered = targetSampleCounts(d);
    if (!(offered & s.samples)) {
      std::string counts;
      for (uint32_t n = 1; n <= 64; n *= 2)
        if (offered & n) counts += (counts.empty() ? "" : ", ") + std::to_string(n);
      throw std::invalid_argument("MSAA " + std::to_string(options.msaaSamples) + ": the device " + d.name +
                                  " offers " + counts + " samples for the raster targets");
    }
  }
  s.color = createImageArray(d, VK_FORMAT_R32G32B32A32_SFLOAT, {s.width, s.height}, s.chunk,
                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                 VK_IMAGE_USAGE_TRANSFER_DST_BIT);  // starts as the background
  if (s.samples != VK_SAMPLE_COUNT_1_BIT)
    s.msColor = createImageArray(d, VK_FORMAT_R32G32B32A32_SFLOAT, {s.width, s.height}, s.chunk,
                                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
                                 s.samples);
  s.depth = createImageArray(d, VK_FORMAT_D32_SFLOAT, {s.width, s.height}, s.chunk,
                             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, s.samples);
  s.readback = createBuffer(d, static_cast<VkDeviceSize>(s.width) * s.height * 16 * s.chunk,
                            VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  s.views = createBuffer(d, sizeof(shaders::RsView) * Impl::kMaxViews, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VK_CHECK(vkCreateSampler(d.device, &sci, nullptr, &s.sampler));
  sci.compareEnable = VK_TRUE;  // hardware 2×2 depth comparison: lit where ref ≤ stored
  sci.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  VK_CHECK(vkCreateSampler(d.device, &sci, nullptr, &s.shadowSampler));
  sci.compareEnable = VK_FALSE;  // raw depths for the area lights' blocker search
  sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
  VK_CHECK(vkCreateSampler(d.device, &sci, nullptr, &s.depthSampler));

  constexpr VkShaderStageFlags kFrag = VK_SHADER_STAGE_FRAGMENT_BIT;
  constexpr VkDescriptorType kSsbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kImage = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  const VkDescriptorSetLayoutBinding bindings[RS_BINDING_COUNT] = {
      layoutBinding(RS_BINDING_TRIANGLE_MATERIAL, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_MATERIALS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_LIGHTS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_TEXELS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_TEXTURES, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_PROBES, kImage, RS_PROBE_TEXTURES, kFrag),
      layoutBinding(RS_BINDING_ENV_BRDF, kImage, 1, kFrag),
      layoutBinding(RS_BINDING_VIEWS, kSsbo, 1, VK_SHADER_STAGE_VERTEX_BIT | kFrag),
      layoutBinding(RS_BINDING_SHADOW_LIGHTS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_SHADOW_LAYERS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_SHADOW_MAP, kImage, 1, kFrag),
      layoutBinding(RS_BINDING_SHADOW_TRANSMIT, kImage, 1, kFrag),
      layoutBinding(RS_BINDING_PROBE_POSITIONS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_PROBE_MOMENTS, kImage, 1, kFrag),
      layoutBinding(RS_BINDING_AREA_LIGHTS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_AREA_CORNERS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_AREA_SHADOW_LAYERS, kSsbo, 1, kFrag),
      layoutBinding(RS_BINDING_AREA_SHADOW_MAP, kImage, 1, kFrag),
      layoutBinding(RS_BINDING_AREA_SHADOW_DEPTH, kImage, 1, kFrag)};
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = RS_BINDING_COUNT;
  lci.pBindings = bindings;
  VK_CHECK(vkCreateDescriptorSetLayout(d.device, &lci, nullptr, &s.setLayout));
  s.layout = createPipelineLayout(d, s.setLayout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                                  sizeof(shaders::RsPushConstants));
  s.pipelineFor(0, RS_PASS_OPAQUE);
  createShadowMaps(d, options.shadowMapSize, options.maxShadowLayers, options.shadowCascades, s.setLayout, s.shadows);
  createShadowMaps(d, options.areaShadowMapSize, options.maxShadowLayers, 1, s.setLayout, s.areaShadows);
  createProbeVisibility(d, s.setLayout, s.visibility);
  setProbeVisibilityScene(scene, s.visibility);

  const VkDescriptorPoolSize sizes[2] = {{kSsbo, 12}, {kImage, RS_PROBE_TEXTURES + 6}};
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
  planShadowMaps(d, scene, s.shadows);
  s.planAreaLights(scene);
  s.shadedLights = scene.lights;
  s.shadedMaterials = scene.materials;
  s.push.shadowMapSize = options.shadowMapSize;
  s.push.areaShadowMapSize = options.areaShadowMapSize;
  s.push.maxAnisotropy = options.anisotropy;
  s.push.lightCount = s.gpu.lightCount;
  // No volume yet: a 1³ black one keeps every descriptor valid (and writes them all).
  ProbeGrid one;
  one.dims[0] = one.dims[1] = one.dims[2] = 1;
  s.uploadVolume(makeProbeVolume(one));
}

RasterRenderer::~RasterRenderer() {
  Impl& s = *impl_;
  VulkanDevice& d = *s.d;
  vkDeviceWaitIdle(d.device);
  for (GpuImage& img : s.probeTextures) destroyImage(d, img);
  destroyBuffer(d, s.staging);
  for (GpuImage* img : {&s.envBrdf, &s.color, &s.msColor, &s.depth}) destroyImage(d, *img);
  for (Buffer* b : {&s.readback, &s.views}) destroyBuffer(d, *b);
  destroyShadowMaps(d, s.shadows);
  destroyProbeVisibility(d, s.visibility);
  destroyShadowMaps(d, s.areaShadows);
  destroyAreaLights(d, s.areaBuffers);
  destroyGpuScene(d, s.gpu);
  for (VkSampler sampler : {s.sampler, s.shadowSampler, s.depthSampler})
    if (sampler) vkDestroySampler(d.device, sampler, nullptr);
  if (s.pool) vkDestroyDescriptorPool(d.device, s.pool, nullptr);
  for (auto& [mask, pipeline] : s.pipelines) vkDestroyPipeline(d.device, pipeline, nullptr);
  if (s.layout) vkDestroyPipelineLayout(d.device, s.layout, nullptr);
  if (s.setLayout) vkDestroyDescriptorSetLayout(d.device, s.setLayout, nullptr);
}

void RasterRenderer::setProbes(const ProbeVolume& volume) {
  std::string error;
  if (!checkProbeVolume(volume, error)) throw std::invalid_argument(error);
  const std::vector<float> positions = probePositions(volume);
  Impl& s = *impl_;
  const bool visible = s.options.visibility && volume.count() <= kMaxVisibilityProbes;
  if (visible) {
    // An open direction reads as far as anything in the scene or the grid can be.
    glm::vec3 lo = glm::min(s.sceneMin, glm::vec3(volume.grid.bounds.min[0], volume.grid.bounds.min[1], volume.grid.bounds.min[2]));
    glm::vec3 hi = glm::max(s.sceneMax, glm::vec3(volume.grid.bounds.max[0], volume.grid.bounds.max[1], volume.grid.bounds.max[2]));
    const float farDistance = std::max(2.0f * glm::length(hi - lo), 1.0f);
    const float reach = s.options.visibilityReach > 0.0f
                            ? s.options.visibilityReach * probeVisibilityReach(volume.grid, hi - lo)
                            : std::numeric_limits<float>::infinity();
    s.visibilityFar = farDistance;
    s.visibilityBuilt = true;
    if (buildProbeVisibility(*s.d, s.gpu, s.set, positions, farDistance, reach, s.options.visibilityCulling,
                             s.visibility)) {
      s.timings.visibilityRenderMs = s.visibility.renderMs;
      s.timings.visibilityMomentsMs = s.visibility.momentsMs;
      s.timings.visibilityTriangles = s.visibility.trianglesDrawn;
      s.writeDescriptors();
    }
  }
  s.uploadVolume(volume);
  const GridBounds& b = volume.grid.bounds;
  const uint32_t* n = volume.grid.dims;
  float spacing = 0.0f;
  for (int a = 0; a < 3; ++a)
    if (n[a] > 1) {
      const float step = (b.max[a] - b.min[a]) / static_cast<float>(n[a] - 1);
      spacing = spacing > 0.0f ? std::min(spacing, step) : step;
    }
  s.push.visibility = visible ? 1u : 0u;
  s.push.volumeMin = {b.min[0], b.min[1], b.min[2], 1.0f};
  s.push.volumeMax = {b.max[0], b.max[1], b.max[2], spacing > 0.0f ? spacing : 1.0f};
  impl_->push.volumeDims = {static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2]),
                            volume.zh3PerPixel ? 1.0f : 0.0f};
}

void RasterRenderer::setShading(const scene::Scene& scene) {
  Impl& s = *impl_;
  if (scene.triangleMaterial.size() != s.indexCount / 3 || scene.positions.size() != s.vertexCount)
    throw std::invalid_argument("setShading needs the same geometry (" + scene.name + " differs)");
  vkDeviceWaitIdle(s.d->device);
  const bool moved = scene.positions != s.positions;
  std::vector<uint32_t> redraw;  // probes whose depth cubes the moved triangles reach
  if (moved) s.shadowBefore = s.positions;
  if (moved) {  // moving geometry: the vertex stream every pass draws from, in place
    if (s.visibilityBuilt && s.push.visibility) redraw = probesNearMovedGeometry(s.visibility, s.positions, scene.positions, scene.indices);
    std::memcpy(s.gpu.accel.positions.mapped, scene.positions.data(), scene.positions.size() * sizeof(glm::vec3));
    s.positions = scene.positions;
  }
  if (s.surfaces.changedBy(scene)) uploadGpuSurfaces(*s.d, scene, s.gpu);  // and the shading
  else uploadGpuShading(*s.d, scene, s.gpu);
  if (moved) {
    // New clusters (their bounds moved); the depth cubes of the probes within reach of a moved
    // triangle are drawn again, the others keep theirs.
    // Without a visibility in use the next build draws every probe (nothing cached survives a move).
    setProbeVisibilityScene(scene, s.visibility, s.visibilityBuilt && s.push.visibility);
    s.writeDescriptors();  // the uploads above replaced buffers the cut-out depth pass reads
    s.timings.geometryMoves += 1;
    s.timings.visibilityProbesRedrawn =
        redrawProbeVisibility(*s.d, s.gpu, s.set, redraw, s.visibilityFar, s.options.visibilityCulling, s.visibility);
    if (s.timings.visibilityProbesRedrawn > 0) {
      s.timings.visibilityRenderMs = s.visibility.renderMs;
      s.timings.visibilityMomentsMs = s.visibility.momentsMs;
      s.timings.visibilityTriangles = s.visibility.trianglesDrawn;
    } else {
      s.timings.visibilityRenderMs = s.timings.visibilityMomentsMs = 0.0;
      s.timings.visibilityTriangles = 0;
    }
  }
  s.push.lightCount = s.gpu.lightCount;
  // Shadow maps: planned again when the lights or materials changed (or nothing moved, as a caller
  // that sets the same scene asks for); when only vertices moved under the same lights, only the
  // layers that see a moved triangle are drawn again.
  const bool sameLights = moved && scene.lights == s.shadedLights && scene.materials == s.shadedMaterials;
  if (sameLights) {
    markLayersOfMovedGeometry(s.shadowBefore, scene.positions, scene.indices, s.shadows);
  } else {
    planShadowMaps(*s.d, scene, s.shadows);
  }
  scene::AreaLightSet areas = scene::extractAreaLights(scene, s.options.areaLights);
  if (sameLights && sameAreaLights(areas, s.areaSet)) {
    markLayersOfMovedGeometry(s.shadowBefore, scene.positions, scene.indices, s.areaShadows);
  } else {
    s.planAreaLights(scene);
  }
  s.shadedLights = scene.lights;
  s.shadedMaterials = scene.materials;
  s.writeDescriptors();
}

void RasterRenderer::setRenderScale(float scale) {
  if (!(scale > 0.0f && scale <= 1.0f)) throw std::invalid_argument("render scale must be in (0, 1]");
  Impl& s = *impl_;
  const uint32_t n = s.options.samplesPerSide;
  const auto side = [&](uint32_t target) {
    const auto image = static_cast<uint32_t>(std::lround(static_cast<double>(target / n) * scale));
    return std::clamp(image, 1u, target / n) * n;
  };
  s.renderScale = scale;
  s.drawWidth = side(s.width);
  s.drawHeight = side(s.height);
}

float RasterRenderer::renderScale() const { return impl_->renderScale; }

void RasterRenderer::setAreaLights(const scene::Scene& scene, const scene::AreaLightOptions& options) {
  impl_->options.areaLights = options;
  setShading(scene);
}

std::vector<Image> RasterRenderer::renderViews(const std::vector<ViewInfo>& views) {
  Impl& s = *impl_;
  if (views.size() > Impl::kMaxViews)
    throw std::invalid_argument("at most " + std::to_string(Impl::kMaxViews) + " views per view set");
  std::vector<Image> out(views.size());
  fitShadowCascades(views, s.shadows);
  drawShadowMaps(*s.d, s.gpu, s.indexCount, s.set, s.shadows);
  s.timings.shadowMs = s.shadows.lastDrawMs;
  s.timings.shadowLayersDrawn = s.shadows.lastLayersDrawn;
  drawShadowMaps(*s.d, s.gpu, s.indexCount, s.set, s.areaShadows);
  s.timings.areaShadowMs = s.areaShadows.lastDrawMs;
  s.timings.areaShadowLayersDrawn = s.areaShadows.lastLayersDrawn;
  const auto t0 = Clock::now();
  auto* dst = static_cast<shaders::RsView*>(s.views.mapped);
  s.inverseViewProj.resize(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    s.inverseViewProj[k] = glm::inverse(views[k].viewProj);
    std::memcpy(&dst[k].viewProj, &views[k].viewProj[0][0], sizeof(float) * 16);
    dst[k].eye = {views[k].eye.x, views[k].eye.y, views[k].eye.z, 1.0f};
  }
  const auto count = static_cast<uint32_t>(views.size());
  for (uint32_t first = 0; first < count; first += s.chunk) s.renderChunk(first, std::min(s.chunk, count - first), out);
  s.timings.viewsMs = msSince(t0);
  return out;
}

Image RasterRenderer::render(const glm::mat4& viewProj, const glm::vec3& eye) {
  ViewInfo view;
  view.viewProj = viewProj;
  view.eye = eye;
  return std::move(renderViews({view})[0]);
}

glm::mat4 RasterRenderer::viewProjection(const CameraView& c) const {
  const float aspect = static_cast<float>(impl_->width) / static_cast<float>(impl_->height);
  return vulkanPerspective(c.yfov, aspect, 0.01f, 200.0f) * glm::lookAtRH(c.position, c.position + c.forward, c.up);
}

bool RasterRenderer::visibilityActive() const { return impl_->push.visibility != 0u; }
uint32_t RasterRenderer::visibilityBytesPerProbe() { return kVisibilityBytesPerProbe; }
uint32_t RasterRenderer::visibilityMaxProbes() { return kMaxVisibilityProbes; }
uint32_t RasterRenderer::visibilityMapTexels() { return RS_VIS_OCT; }
glm::vec2 RasterRenderer::probeMoments(uint32_t probe, const glm::vec3& dir) const {
  return probeMomentsAt(impl_->visibility, probe, dir);
}

uint32_t RasterRenderer::chunkSize() const { return impl_->chunk; }
const RasterTimings& RasterRenderer::timings() const { return impl_->timings; }
const scene::AreaLightSet& RasterRenderer::areaLights() const { return impl_->areaSet; }

}  // namespace probecast::renderer
