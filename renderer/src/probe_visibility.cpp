#include "probe_visibility.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include <glm/gtc/matrix_transform.hpp>
#include <meshoptimizer.h>

#include "probecast/codec/probe_offsets.h"
#include "probecast/renderer/view_sets.h"
#include "shadow_maps.h"
#include "vk_pipeline.h"

namespace probecast::renderer {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr uint32_t kCube = kVisibilityCubeSize;
// The lobes are summed over the cube reduced 2× per side (sums of r and r² over 2×2 texels keep
// both moments; only the weight inside a block is taken as constant): a quarter of the taps.
constexpr uint32_t kLobeCube = kCube / 2;
constexpr uint32_t kBatchColumns = 16;  // probes per row of the depth atlas (six faces each)
constexpr uint32_t kBatchRows = 16;     // rows of probes per depth atlas: 256 probes per pass
constexpr uint32_t kBatch = kBatchColumns * kBatchRows;
constexpr uint32_t kAtlasW = kBatchColumns * 6 * kCube, kAtlasH = kBatchRows * kCube;
constexpr float kNear = 0.005f;  // metres: a surface nearer than this to a probe is not seen
constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

glm::vec3 vertex(const scene::Scene& s, uint32_t triangle, int corner) {
  return s.positions[s.indices[static_cast<size_t>(triangle) * 3 + static_cast<size_t>(corner)]];
}

// Clusters of consecutive triangles [first, end) of the scene's order, up to
// kVisibilityClusterTriangles each.
std::vector<VisibilityCluster> clustersOf(const scene::Scene& s, uint32_t first, uint32_t end) {
  std::vector<VisibilityCluster> out;
  for (uint32_t k = first; k < end; k += kVisibilityClusterTriangles) {
    VisibilityCluster c;
    c.first = k;
    c.count = std::min(kVisibilityClusterTriangles, end - k);
    c.lo = glm::vec3(std::numeric_limits<float>::max());
    c.hi = -c.lo;
    for (uint32_t t = k; t < k + c.count; ++t)
      for (int v = 0; v < 3; ++v) {
        c.lo = glm::min(c.lo, vertex(s, t, v));
        c.hi = glm::max(c.hi, vertex(s, t, v));
      }
    out.push_back(c);
  }
  return out;
}

// Clusters of consecutive triangles of `indices` (three vertex numbers each), up to
// kVisibilityClusterTriangles each, bounded by `positions`.
std::vector<VisibilityCluster> clustersOf(const std::vector<uint32_t>& indices, const std::vector<glm::vec3>& positions) {
  std::vector<VisibilityCluster> out;
  const auto end = static_cast<uint32_t>(indices.size() / 3);
  for (uint32_t k = 0; k < end; k += kVisibilityClusterTriangles) {
    VisibilityCluster c;
    c.first = k;
    c.count = std::min(kVisibilityClusterTriangles, end - k);
    c.lo = glm::vec3(std::numeric_limits<float>::max());
    c.hi = -c.lo;
    for (size_t i = size_t{3} * k; i < size_t{3} * (k + c.count); ++i) {
      c.lo = glm::min(c.lo, positions[indices[i]]);
      c.hi = glm::max(c.hi, positions[indices[i]]);
    }
    out.push_back(c);
  }
  return out;
}

// The still triangles of `still` (vertex numbers) simplified to `error` metres: coincident
// vertices welded, meshoptimizer's edge collapses within the error, then back to scene numbers.
// Unchanged when the error is 0 or the positions are not finite.
std::vector<uint32_t> simplified(std::vector<uint32_t> still, const std::vector<glm::vec3>& positions, float error) {
  if (!(error > 0.0f) || still.size() < 3) return still;
  std::vector<uint32_t> remap(positions.size());
  const size_t unique = meshopt_generateVertexRemap(remap.data(), still.data(), still.size(), positions.data(),
                                                    positions.size(), sizeof(glm::vec3));
  std::vector<glm::vec3> welded(unique);
  meshopt_remapVertexBuffer(welded.data(), positions.data(), positions.size(), sizeof(glm::vec3), remap.data());
  std::vector<uint32_t> weldedIndices(still.size());
  meshopt_remapIndexBuffer(weldedIndices.data(), still.data(), still.size(), remap.data());
  for (const glm::vec3& v : welded)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return still;
  const float scale = meshopt_simplifyScale(&welded[0].x, unique, sizeof(glm::vec3));
  if (!(scale > 0.0f) || !std::isfinite(scale)) return still;
  std::vector<uint32_t> original(unique, 0);
  for (size_t v = 0; v < positions.size(); ++v)
    if (remap[v] != ~0u) original[remap[v]] = static_cast<uint32_t>(v);
  std::vector<uint32_t> out(weldedIndices.size());
  out.resize(meshopt_simplify(out.data(), weldedIndices.data(), weldedIndices.size(), &welded[0].x, unique,
                              sizeof(glm::vec3), 0, error / scale, 0, nullptr));
  for (uint32_t& i : out) i = original[i];
  return out;
}

// Makes vis.proxy for `error` (again only when the error or a still vertex changed) and its
// clusters at the vertices' current places.
void ensureProxy(ProbeVisibility& vis, float error) {
  bool stillMoved = vis.proxyFrom.size() != vis.vertices.size();
  if (!stillMoved && vis.proxyFrom != vis.vertices)
    for (size_t t = 0; t < vis.opaqueMoving.size() && !stillMoved; ++t)
      for (size_t c = 0; c < 3 && !vis.opaqueMoving[t]; ++c) {
        const uint32_t v = vis.opaqueIndices[t * 3 + c];
        stillMoved = stillMoved || vis.proxyFrom[v] != vis.vertices[v];
      }
  if (error != vis.proxyError || stillMoved) {
    std::vector<uint32_t> still, moving;
    for (size_t t = 0; t < vis.opaqueMoving.size(); ++t) {
      std::vector<uint32_t>& to = vis.opaqueMoving[t] ? moving : still;
      to.insert(to.end(), vis.opaqueIndices.begin() + static_cast<std::ptrdiff_t>(t * 3),
                vis.opaqueIndices.begin() + static_cast<std::ptrdiff_t>(t * 3 + 3));
    }
    vis.proxy = simplified(std::move(still), vis.vertices, error);
    vis.proxy.insert(vis.proxy.end(), moving.begin(), moving.end());
    vis.proxyError = error;
    vis.proxyFrom = vis.vertices;
  }
  vis.opaque = clustersOf(vis.proxy, vis.vertices);
}

float proxyErrorFor(float reach) { return std::isfinite(reach) ? kVisibilityProxyError * reach : 0.0f; }

// Whether a box (relative to the probe) may meet face f's 90° pyramid (the points whose coordinate
// on the face's axis, signed, is at least the absolute value of the other two): each bounding plane
// of the pyramid is linear, so the box meets its side when the corner farthest that way does.
// Generous by a hair of the box's size, so that triangles on a boundary are kept.
bool clusterInFace(const glm::vec3& lo, const glm::vec3& hi, uint32_t f) {
  const int axis = static_cast<int>(f / 2);
  const float along = f % 2 == 0 ? hi[axis] : -lo[axis];  // the farthest the box goes along the face's axis
  const float slack = 1e-4f * (glm::length(hi - lo) + glm::length(hi + lo)) + 1e-6f;
  if (along <= -slack) return false;
  for (int b = 0; b < 3; ++b)
    if (b != axis && (along - lo[b] < -slack || along + hi[b] < -slack)) return false;
  return true;
}

// Whether a box (relative to the probe) has any point within `reach` of the probe.
bool clusterInReach(const glm::vec3& lo, const glm::vec3& hi, float reach) {
  const glm::vec3 nearest = glm::clamp(glm::vec3(0.0f), lo, hi);
  return glm::dot(nearest, nearest) <= reach * reach;
}

// The six 90° faces seen from the origin (+x −x +y −y +z −z), world → Vulkan clip.
std::vector<glm::mat4> cubeFaceViews(float farDistance) {
  static const glm::vec3 kDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const glm::vec3 kUp[6] = {{0, 1, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};
  const glm::mat4 proj = vulkanPerspective(glm::radians(90.0f), 1.0f, kNear, farDistance);
  std::vector<glm::mat4> faces;
  for (int f = 0; f < 6; ++f) faces.push_back(proj * glm::lookAtRH(glm::vec3(0.0f), kDir[f], kUp[f]));
  return faces;
}

// Centre of texel i of a face or an octahedral interior, in [-1, 1].
float texelCentre(uint32_t i, uint32_t n) { return (static_cast<float>(i) + 0.5f) / static_cast<float>(n) * 2.0f - 1.0f; }

// The direction of every cube texel (face-major, then row, then column) and its solid angle
// (∝ (1 + u² + v²)^(-3/2) for face coordinates u, v).
struct CubeTexels {
  std::vector<glm::vec3> dir;
  std::vector<float> solidAngle;
};

const CubeTexels& cubeTexels() {
  static const CubeTexels texels = [] {
    CubeTexels t;
    for (uint32_t f = 0; f < 6; ++f)
      for (uint32_t y = 0; y < kLobeCube; ++y)
        for (uint32_t x = 0; x < kLobeCube; ++x) {
          const float u = texelCentre(x, kLobeCube), v = texelCentre(y, kLobeCube);
          t.dir.push_back(cubeTexelDirection(f, x, y, kLobeCube));
          t.solidAngle.push_back(std::pow(1.0f + u * u + v * v, -1.5f));
        }
    return t;
  }();
  return texels;
}

// For every texel of a tile (borders folded back across the octahedron's edges, so they repeat
// the texel they stand for), the cube texels of its lobe and their normalised weights.
struct LobeTap {
  uint32_t cube;
  float weight;
};

const std::vector<std::vector<LobeTap>>& lobeTaps() {
  static const std::vector<std::vector<LobeTap>> taps = [] {
    const CubeTexels& cube = cubeTexels();
    std::vector<std::vector<LobeTap>> all(RS_VIS_TILE * RS_VIS_TILE);
    for (uint32_t ty = 0; ty < RS_VIS_TILE; ++ty)
      for (uint32_t tx = 0; tx < RS_VIS_TILE; ++tx) {
        glm::vec2 e((static_cast<float>(tx) - 0.5f) / RS_VIS_OCT * 2.0f - 1.0f,
                    (static_cast<float>(ty) - 0.5f) / RS_VIS_OCT * 2.0f - 1.0f);
        // Across an edge of the square, (1 + ε, v) is the same point as (1 − ε, −v).
        if (std::abs(e.x) > 1.0f) e = {std::copysign(2.0f, e.x) - e.x, -e.y};
        if (std::abs(e.y) > 1.0f) e = {-e.x, std::copysign(2.0f, e.y) - e.y};
        const glm::vec3 d = octDecode(e);
        std::vector<LobeTap>& list = all[ty * RS_VIS_TILE + tx];
        double sum = 0.0;
        for (uint32_t s = 0; s < cube.dir.size(); ++s) {
          const float c = glm::dot(d, cube.dir[s]);
          if (c <= 0.0f) continue;
          const float w = std::pow(c, kVisibilityLobePower) * cube.solidAngle[s];
          if (w < 1e-4f) continue;
          list.push_back({s, w});
          sum += w;
        }
        for (LobeTap& t : list) t.weight = static_cast<float>(t.weight / sum);
      }
    return all;
  }();
  return taps;
}

void destroyOwned(VulkanDevice& d, ProbeVisibility& vis) {
  destroyImage(d, vis.moments);
  destroyBuffer(d, vis.positions);
}

// Uploads an atlas of `width` × `height` RG texels and the positions, replacing the old ones once
// both are made.
void uploadMoments(VulkanDevice& d, std::vector<float> atlas, uint32_t width, uint32_t height,
                   const std::vector<float>& positions, float reach, ProbeVisibility& vis) {
  const size_t count = positions.size() / 3;
  std::vector<float> xyzw(std::max<size_t>(count, 1) * 4, 0.0f);
  for (size_t p = 0; p < std::max<size_t>(count, 1); ++p) {
    for (int c = 0; c < 3 && p < count; ++c) xyzw[p * 4 + c] = positions[p * 3 + c];
    xyzw[p * 4 + 3] = std::min(reach, std::numeric_limits<float>::max());  // finite for the shader
  }
  GpuImage image;
  Buffer pos, staging;
  try {
    pos = createBufferWithData(d, xyzw.data(), xyzw.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    staging = createBufferWithData(d, atlas.data(), atlas.size() * sizeof(float), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    image = createImage(d, VK_FORMAT_R32G32_SFLOAT, {width, height, 1},
                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    submitAndWait(d, [&](VkCommandBuffer cmd) {
      transitionImage(cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {width, height, 1};
      vkCmdCopyBufferToImage(cmd, staging.buffer, image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      transitionImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
  } catch (...) {
    destroyImage(d, image);
    destroyBuffer(d, pos);
    destroyBuffer(d, staging);
    throw;
  }
  destroyBuffer(d, staging);
  destroyOwned(d, vis);
  vis.moments = image;
  vis.positions = pos;
  vis.atlas = std::move(atlas);
  vis.atlasWidth = width;
  vis.atlasHeight = height;
}

// One indexed draw per run of consecutive clusters that a face keeps.
struct DrawRun {
  uint32_t firstTriangle, triangles;
};

// The runs of `clusters` that face f of a probe at `probe` draws: all of them without culling.
void faceRuns(const std::vector<VisibilityCluster>& clusters, const glm::vec3& probe, uint32_t f, float reach, bool cull,
              std::vector<DrawRun>& runs) {
  runs.clear();
  for (const VisibilityCluster& c : clusters) {
    if (cull && !(clusterInReach(c.lo - probe, c.hi - probe, reach) && clusterInFace(c.lo - probe, c.hi - probe, f)))
      continue;
    if (!runs.empty() && runs.back().firstTriangle + runs.back().triangles == c.first)
      runs.back().triangles += c.count;
    else
      runs.push_back({c.first, c.count});
  }
}

// One batch of depth cubes: its own depth atlas, readback and gathered indices, so that the host
// gathers the next batch and filters the last one while the device draws this one.
struct DepthBatch {
  GpuImage depth;
  Buffer readback, gathered;
  Submission submission;
  size_t first = 0;
  uint32_t n = 0;
  bool listed = false;  // draw only the probes `only` marks
  std::vector<uint8_t> only;
  bool inFlight = false;
};

void destroyDepthBatch(VulkanDevice& d, DepthBatch& b) {
  finishSubmission(d, b.submission);
  destroyBuffer(d, b.gathered);
  destroyBuffer(d, b.readback);
  destroyImage(d, b.depth);
  b = DepthBatch{};
}

// Starts drawing the depth cubes of probes [b.first, b.first + b.n) into b.depth (kAtlasW ×
// kAtlasH) and copying them to b.readback; finishDepthCubes waits and reads them. Returns the
// triangles drawn.
uint64_t startDepthCubes(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials,
                         const std::vector<float>& positions, const std::vector<glm::mat4>& faces, float reach,
                         bool cull, const ProbeVisibility& vis, DepthBatch& batch) {
  const size_t first = batch.first;
  const uint32_t n = batch.n;
  const std::vector<uint8_t>* only = batch.listed ? &batch.only : nullptr;
  GpuImage& depth = batch.depth;
  Buffer& readback = batch.readback;
  Buffer& gathered = batch.gathered;
  uint64_t drawn = 0;
  // The opaque triangles each face keeps, gathered into one index list per face and drawn with one
  // call per face (depth only: nothing needs their numbers in the scene): small clusters cull
  // tightly without a draw call each. The same triangles in the same order: the same depths.
  struct FaceDraw {
    uint32_t firstIndex = 0, indexCount = 0, probe = 0, face = 0;
  };
  std::vector<FaceDraw> faceDraws;
  if (!vis.opaque.empty()) {
    const uint32_t* indices = vis.proxy.data();
    const auto* vertices = static_cast<const glm::vec3*>(gpu.accel.positions.mapped);
    // Probes [from, to) of the batch into their own list (one per thread; joined in order below).
    struct Part {
      std::vector<uint32_t> list;
      std::vector<FaceDraw> draws;
      uint64_t triangles = 0;
    };
    auto gather = [&](uint32_t from, uint32_t to, Part& out) {
      std::vector<const VisibilityCluster*> near;
      for (uint32_t k = from; k < to; ++k) {
        if (only && !(*only)[k]) continue;
        const glm::vec3 probe(positions[(first + k) * 3], positions[(first + k) * 3 + 1], positions[(first + k) * 3 + 2]);
        near.clear();  // the clusters within reach, once per probe; then each face's pyramid
        for (const VisibilityCluster& c : vis.opaque)
          if (!cull || clusterInReach(c.lo - probe, c.hi - probe, reach)) near.push_back(&c);
        for (uint32_t f = 0; f < 6; ++f) {
          FaceDraw fd{static_cast<uint32_t>(out.list.size()), 0, k, f};
          for (const VisibilityCluster* cl : near) {
            if (cull && !clusterInFace(cl->lo - probe, cl->hi - probe, f)) continue;
            for (uint32_t t = cl->first; t < cl->first + cl->count; ++t) {
              const uint32_t* tri = indices + size_t{3} * t;
              if (cull) {  // each triangle's own box, as the clusters' were tested
                const glm::vec3 a = vertices[tri[0]] - probe, b = vertices[tri[1]] - probe, c = vertices[tri[2]] - probe;
                const glm::vec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
                if (!(clusterInReach(lo, hi, reach) && clusterInFace(lo, hi, f))) continue;
              }
              out.list.insert(out.list.end(), tri, tri + 3);
              ++out.triangles;
            }
          }
          fd.indexCount = static_cast<uint32_t>(out.list.size()) - fd.firstIndex;
          if (fd.indexCount > 0) out.draws.push_back(fd);
        }
      }
    };
    // Culling is CPU work while the device waits: split over the cores (at most 8 parts).
    const uint32_t parts = std::clamp<uint32_t>(std::thread::hardware_concurrency(), 1, std::min<uint32_t>(8, n));
    std::vector<Part> part(parts);
    std::vector<std::thread> workers;
    for (uint32_t i = 1; i < parts; ++i)
      workers.emplace_back(gather, n * i / parts, n * (i + 1) / parts, std::ref(part[i]));
    gather(0, n / parts, part[0]);
    for (std::thread& w : workers) w.join();
    std::vector<uint32_t> list;
    for (Part& pt : part) {
      const auto offset = static_cast<uint32_t>(list.size());
      for (FaceDraw fd : pt.draws) {
        fd.firstIndex += offset;
        faceDraws.push_back(fd);
      }
      list.insert(list.end(), pt.list.begin(), pt.list.end());
      drawn += pt.triangles;
    }
    gathered = createBufferWithData(d, list.data(), list.size() * sizeof(uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  }
  batch.submission = submitAsync(d, [&](VkCommandBuffer cmd) {
    transitionImage(cmd, depth, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    const VkRenderingAttachmentInfo depthInfo =
        clearedAttachment(depth.view, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_STORE);
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {kAtlasW, kAtlasH}};
    ri.layerCount = 1;
    ri.pDepthAttachment = &depthInfo;
    vkCmdBeginRendering(cmd, &ri);
    const VkBuffer streams[3] = {gpu.accel.positions.buffer, gpu.normals.buffer, gpu.texcoords.buffer};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    vkCmdBindVertexBuffers(cmd, 0, 3, streams, offsets);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, vis.layout, 0, 1, &materials, 0, nullptr);
    std::vector<DrawRun> runs;
    auto placeFace = [&](uint32_t k, uint32_t f, const glm::vec3& probe) {
      const auto x = static_cast<int32_t>(((k % kBatchColumns) * 6 + f) * kCube);
      const auto y = static_cast<int32_t>((k / kBatchColumns) * kCube);
      const VkViewport viewport{static_cast<float>(x), static_cast<float>(y), kCube, kCube, 0.0f, 1.0f};
      const VkRect2D scissor{{x, y}, {kCube, kCube}};
      vkCmdSetViewport(cmd, 0, 1, &viewport);
      vkCmdSetScissor(cmd, 0, 1, &scissor);
      shaders::RsShadowPush push{};
      const glm::mat4 vp = faces[f] * glm::translate(glm::mat4(1.0f), -probe);
      std::memcpy(&push.viewProj, &vp[0][0], sizeof push.viewProj);
      return push;
    };
    auto probeAt = [&](uint32_t k) {
      return glm::vec3(positions[(first + k) * 3], positions[(first + k) * 3 + 1], positions[(first + k) * 3 + 2]);
    };
    if (!faceDraws.empty()) {  // the opaque triangles, one draw per face
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, vis.pipeline);
      vkCmdBindIndexBuffer(cmd, gathered.buffer, 0, VK_INDEX_TYPE_UINT32);
      for (const FaceDraw& fd : faceDraws) {
        const shaders::RsShadowPush push = placeFace(fd.probe, fd.face, probeAt(fd.probe));
        vkCmdPushConstants(cmd, vis.layout, kStages, 0, sizeof push, &push);
        vkCmdDrawIndexed(cmd, fd.indexCount, 1, fd.firstIndex, 0, 0);
      }
    }
    vkCmdBindIndexBuffer(cmd, gpu.accel.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    // The cut-outs, by runs of the scene's order (shadow.frag finds each one's material by number).
    for (int pass = 1; pass < 2; ++pass) {
      const std::vector<VisibilityCluster>& clusters = vis.cutouts;
      if (clusters.empty()) continue;
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, vis.cutoutPipeline);
      for (uint32_t k = 0; k < n; ++k) {
        if (only && !(*only)[k]) continue;
        const glm::vec3 probe = probeAt(k);
        for (uint32_t f = 0; f < 6; ++f) {
          faceRuns(clusters, probe, f, reach, cull, runs);
          if (runs.empty()) continue;
          shaders::RsShadowPush push = placeFace(k, f, probe);
          for (const DrawRun& run : runs) {
            push.primitiveBase = run.firstTriangle;
            vkCmdPushConstants(cmd, vis.layout, kStages, 0, sizeof push, &push);
            vkCmdDrawIndexed(cmd, 3 * run.triangles, 1, 3 * run.firstTriangle, 0, 0);
            drawn += run.triangles;
          }
        }
      }
    }
    vkCmdEndRendering(cmd);
    transitionImage(cmd, depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    region.imageExtent = {kAtlasW, kAtlasH, 1};
    vkCmdCopyImageToBuffer(cmd, depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &region);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
  });
  batch.inFlight = true;
  return drawn;
}

// Waits for a batch startDepthCubes began and reads its distances into `distances` (6 kCube² per
// probe, cubeTexels' order), clamped to `reach` (an open direction reads farDistance, or reach if
// nearer).
void finishDepthCubes(VulkanDevice& d, const std::vector<glm::mat4>& faces, float farDistance, float reach,
                      DepthBatch& b, std::vector<float>& distances) {
  finishSubmission(d, b.submission);
  b.inFlight = false;
  destroyBuffer(d, b.gathered);
  const uint32_t n = b.n;
  // Depth → distance: unproject through the face's inverse (the probe at the origin).
  std::vector<glm::mat4> inverse;
  for (const glm::mat4& f : faces) inverse.push_back(glm::inverse(f));
  const float* z = static_cast<const float*>(b.readback.mapped);
  distances.resize(static_cast<size_t>(n) * 6 * kCube * kCube);
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t f = 0; f < 6; ++f)
      for (uint32_t ty = 0; ty < kCube; ++ty)
        for (uint32_t tx = 0; tx < kCube; ++tx) {
          const uint32_t ax = ((k % kBatchColumns) * 6 + f) * kCube + tx, ay = (k / kBatchColumns) * kCube + ty;
          const float depthValue = z[static_cast<size_t>(ay) * kAtlasW + ax];
          float r = std::min(farDistance, reach);
          if (depthValue < 1.0f) {
            const glm::vec4 p = inverse[f] * glm::vec4(texelCentre(tx, kCube), texelCentre(ty, kCube), depthValue, 1.0f);
            r = glm::length(glm::vec3(p) / p.w);
            r = std::min(r, reach);  // the same whether or not what lies beyond was drawn
          }
          distances[((static_cast<size_t>(k) * 6 + f) * kCube + ty) * kCube + tx] = r;
        }
}

}  // namespace

glm::vec3 cubeTexelDirection(uint32_t face, uint32_t x, uint32_t y, uint32_t size) {
  static const std::vector<glm::mat4> inverse = [] {
    std::vector<glm::mat4> out;
    for (const glm::mat4& vp : cubeFaceViews(100.0f)) out.push_back(glm::inverse(vp));
    return out;
  }();
  const glm::vec4 p = inverse.at(face) * glm::vec4(texelCentre(x, size), texelCentre(y, size), 0.5f, 1.0f);
  return glm::normalize(glm::vec3(p) / p.w);
}

glm::vec2 octEncode(const glm::vec3& v) {
  glm::vec2 e = glm::vec2(v.x, v.y) / (std::abs(v.x) + std::abs(v.y) + std::abs(v.z));
  if (v.z < 0.0f)
    e = glm::vec2((1.0f - std::abs(e.y)) * (e.x >= 0.0f ? 1.0f : -1.0f), (1.0f - std::abs(e.x)) * (e.y >= 0.0f ? 1.0f : -1.0f));
  return e;
}

glm::vec3 octDecode(glm::vec2 e) {
  glm::vec3 v(e.x, e.y, 1.0f - std::abs(e.x) - std::abs(e.y));
  if (v.z < 0.0f)
    v = glm::vec3((1.0f - std::abs(e.y)) * (e.x >= 0.0f ? 1.0f : -1.0f), (1.0f - std::abs(e.x)) * (e.y >= 0.0f ? 1.0f : -1.0f), v.z);
  return glm::normalize(v);
}

void octahedralMoments(const float* cubeDistances, uint32_t size, float* tile) {
  if (size != kCube) throw std::invalid_argument("depth cubes are " + std::to_string(kCube) + " texels per side");
  const std::vector<std::vector<LobeTap>>& taps = lobeTaps();
  float r1[6 * kLobeCube * kLobeCube], r2[6 * kLobeCube * kLobeCube];
  for (uint32_t f = 0; f < 6; ++f)
    for (uint32_t y = 0; y < kLobeCube; ++y)
      for (uint32_t x = 0; x < kLobeCube; ++x) {
        float sum = 0.0f, square = 0.0f;
        for (uint32_t k = 0; k < 4; ++k) {
          const float r = cubeDistances[(f * kCube + 2 * y + k / 2) * kCube + 2 * x + k % 2];
          sum += r;
          square += r * r;
        }
        r1[(f * kLobeCube + y) * kLobeCube + x] = 0.25f * sum;
        r2[(f * kLobeCube + y) * kLobeCube + x] = 0.25f * square;
      }
  for (size_t t = 0; t < taps.size(); ++t) {
    float mean = 0.0f, square = 0.0f;
    for (const LobeTap& tap : taps[t]) {
      mean += tap.weight * r1[tap.cube];
      square += tap.weight * r2[tap.cube];
    }
    tile[t * 2] = mean;
    tile[t * 2 + 1] = square;
  }
}

glm::vec2 probeMomentsAt(const ProbeVisibility& vis, uint32_t probe, const glm::vec3& dir) {
  const glm::vec2 e = octEncode(glm::normalize(dir));
  const auto ix = std::min<uint32_t>(RS_VIS_OCT - 1, static_cast<uint32_t>((e.x * 0.5f + 0.5f) * RS_VIS_OCT));
  const auto iy = std::min<uint32_t>(RS_VIS_OCT - 1, static_cast<uint32_t>((e.y * 0.5f + 0.5f) * RS_VIS_OCT));
  const uint32_t x = (probe % RS_VIS_TILES_PER_ROW) * RS_VIS_TILE + 1 + ix;
  const uint32_t y = (probe / RS_VIS_TILES_PER_ROW) * RS_VIS_TILE + 1 + iy;
  const size_t i = (static_cast<size_t>(y) * vis.atlasWidth + x) * 2;
  if (i + 1 >= vis.atlas.size()) return glm::vec2(0.0f);
  return {vis.atlas[i], vis.atlas[i + 1]};
}

void createProbeVisibility(VulkanDevice& d, VkDescriptorSetLayout materials, ProbeVisibility& out) {
  out.layout = createPipelineLayout(d, materials, kStages, sizeof(shaders::RsShadowPush));
  createDepthPipelines(d, out.layout, false, out.pipeline, out.cutoutPipeline);
  // One tile of a probe that sees nothing: E[r] large, zero variance — every point visible.
  std::vector<float> atlas(RS_VIS_TILE * RS_VIS_TILE * 2);
  for (size_t t = 0; t < atlas.size(); t += 2) {
    atlas[t] = 1e6f;
    atlas[t + 1] = 1e12f;
  }
  uploadMoments(d, std::move(atlas), RS_VIS_TILE, RS_VIS_TILE, {0.0f, 0.0f, 0.0f},
                std::numeric_limits<float>::infinity(), out);
}

void setProbeVisibilityScene(const scene::Scene& scene, ProbeVisibility& vis, bool keepBuilt) {
  // finalizeScene keeps each class one run, in Morton order within it: runs of it are compact.
  const uint32_t opaque = scene::leadingTrianglesBelowClass(scene, 1);
  vis.opaqueIndices.assign(scene.indices.begin(), scene.indices.begin() + static_cast<std::ptrdiff_t>(opaque) * 3);
  vis.opaqueMoving = scene::movingTriangles(scene);
  vis.opaqueMoving.resize(opaque);
  vis.vertices = scene.positions;
  vis.opaque.clear();  // made with the proxy, before the next drawing
  vis.cutouts = clustersOf(scene, opaque, scene::leadingTrianglesBelowClass(scene, 2));
  if (!keepBuilt) vis.builtFor.clear();  // new geometry: the next build draws again
}

std::vector<uint32_t> probesNearMovedGeometry(const ProbeVisibility& vis, const std::vector<glm::vec3>& before,
                                              const std::vector<glm::vec3>& after,
                                              const std::vector<uint32_t>& indices) {
  const size_t count = vis.builtFor.size() / 3;
  std::vector<uint8_t> near(count, 0);
  const bool unlimited = !std::isfinite(vis.builtReach);
  for (size_t t = 0; t + 2 < indices.size() && !unlimited; t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (before[v[0]] == after[v[0]] && before[v[1]] == after[v[1]] && before[v[2]] == after[v[2]]) continue;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (uint32_t i : v) {
      lo = glm::min(lo, glm::min(before[i], after[i]));
      hi = glm::max(hi, glm::max(before[i], after[i]));
    }
    for (size_t p = 0; p < count; ++p) {
      if (near[p]) continue;
      const glm::vec3 q(vis.builtFor[3 * p], vis.builtFor[3 * p + 1], vis.builtFor[3 * p + 2]);
      near[p] = glm::length(glm::clamp(q, lo, hi) - q) <= vis.builtReach;
    }
  }
  std::vector<uint32_t> out;
  for (size_t p = 0; p < count; ++p)
    if (near[p] || unlimited) out.push_back(static_cast<uint32_t>(p));
  return out;
}

namespace {

// Draws the depth cubes of the probes at `positions` (all, or those `listed` marks), filters their
// moments into `atlas` (`atlasWidth` texels wide, tiles in probe order) and uploads it. Each batch
// is the one a full build draws, so a probe is rasterised at its own place in the depth atlas
// whichever probes are drawn with it (another place may round differently).
void drawIntoAtlas(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials, const std::vector<float>& positions,
                   const std::vector<uint8_t>* listed, float farDistance, float reach, bool cull,
                   std::vector<float> atlas, uint32_t atlasWidth, uint32_t atlasHeight, ProbeVisibility& vis) {
  const auto t0 = Clock::now();
  ensureProxy(vis, proxyErrorFor(reach));
  const size_t count = positions.size() / 3;
  const std::vector<glm::mat4> faces = cubeFaceViews(farDistance);
  double momentsMs = 0.0;
  uint64_t drawn = 0;
  // Two batches in turn: while the device draws one, the host gathers the next and filters the
  // one before.
  DepthBatch slot[2];
  try {
    for (DepthBatch& b : slot) {
      b.depth = createImage(d, VK_FORMAT_D32_SFLOAT, {kAtlasW, kAtlasH, 1},
                            VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
      b.readback = createBuffer(d, static_cast<VkDeviceSize>(kAtlasW) * kAtlasH * sizeof(float),
                                VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }
    std::vector<float> distances, tile(RS_VIS_TILE * RS_VIS_TILE * 2);
    auto finish = [&](DepthBatch& b) {
      if (!b.inFlight) return;
      finishDepthCubes(d, faces, farDistance, reach, b, distances);
      const auto m0 = Clock::now();
      for (uint32_t k = 0; k < b.n; ++k) {
        if (b.listed && !b.only[k]) continue;
        octahedralMoments(distances.data() + static_cast<size_t>(k) * 6 * kCube * kCube, kCube, tile.data());
        const size_t p = b.first + k;
        const size_t x0 = (p % RS_VIS_TILES_PER_ROW) * RS_VIS_TILE, y0 = (p / RS_VIS_TILES_PER_ROW) * RS_VIS_TILE;
        for (uint32_t ty = 0; ty < RS_VIS_TILE; ++ty)
          std::copy_n(tile.data() + ty * RS_VIS_TILE * 2, RS_VIS_TILE * 2,
                      atlas.data() + ((y0 + ty) * atlasWidth + x0) * 2);
      }
      momentsMs += msSince(m0);
    };
    uint32_t turn = 0;
    for (size_t first = 0; first < count; first += kBatch) {
      DepthBatch& b = slot[turn];
      b.first = first;
      b.n = static_cast<uint32_t>(std::min<size_t>(kBatch, count - first));
      b.listed = listed != nullptr;
      if (listed) {
        b.only.assign(listed->begin() + static_cast<std::ptrdiff_t>(first),
                      listed->begin() + static_cast<std::ptrdiff_t>(first + b.n));
        if (std::find(b.only.begin(), b.only.end(), 1) == b.only.end()) continue;
      }
      drawn += startDepthCubes(d, gpu, materials, positions, faces, reach, cull, vis, b);
      turn ^= 1u;
      finish(slot[turn]);  // the batch before, drawn while this one was gathered
    }
    finish(slot[turn ^ 1u]);
    finish(slot[turn]);
  } catch (...) {
    for (DepthBatch& b : slot) destroyDepthBatch(d, b);
    throw;
  }
  for (DepthBatch& b : slot) destroyDepthBatch(d, b);
  const auto u0 = Clock::now();
  uploadMoments(d, std::move(atlas), atlasWidth, atlasHeight, positions, reach, vis);
  vis.momentsMs = momentsMs + msSince(u0);
  vis.renderMs = msSince(t0) - vis.momentsMs;
  vis.trianglesDrawn = drawn;
}

}  // namespace

uint32_t redrawProbeVisibility(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials,
                               const std::vector<uint32_t>& which, float farDistance, bool cull, ProbeVisibility& vis) {
  if (which.empty() || vis.builtFor.empty()) return 0;
  const size_t count = vis.builtFor.size() / 3;
  std::vector<uint8_t> listed(count, 0);
  for (uint32_t p : which) {
    if (p >= count) throw std::invalid_argument("redrawProbeVisibility: no such probe");
    listed[p] = 1;
  }
  const std::vector<float> built = vis.builtFor;  // uploadMoments replaces vis's copy
  drawIntoAtlas(d, gpu, materials, built, &listed, farDistance, vis.builtReach, cull, vis.atlas, vis.atlasWidth,
                vis.atlasHeight, vis);
  return static_cast<uint32_t>(which.size());
}

float probeVisibilityReach(const ProbeGrid& grid, const glm::vec3& sceneExtent) {
  glm::vec3 cell(0.0f);
  float spacing = std::numeric_limits<float>::max();
  for (int a = 0; a < 3; ++a) {
    cell[a] = grid.dims[a] > 1 ? probeCellSize(grid, a) : sceneExtent[a];
    if (grid.dims[a] > 1) spacing = std::min(spacing, cell[a]);
  }
  if (spacing == std::numeric_limits<float>::max()) return std::numeric_limits<float>::infinity();  // one probe
  return 1.5f * glm::length(cell) + 0.25f * spacing;
}

bool buildProbeVisibility(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials,
                          const std::vector<float>& positions, float farDistance, float reach, bool cull,
                          ProbeVisibility& vis) {
  if (positions == vis.builtFor && reach == vis.builtReach) return false;
  if (!(reach > 0.0f)) throw std::invalid_argument("probe visibility reach must be positive");
  const size_t count = positions.size() / 3;
  if (count == 0 || count > kMaxVisibilityProbes)
    throw std::invalid_argument("probe visibility takes 1.." + std::to_string(kMaxVisibilityProbes) + " probes, not " +
                                std::to_string(count));
  const auto columns = static_cast<uint32_t>(std::min<size_t>(count, RS_VIS_TILES_PER_ROW));
  const auto rows = static_cast<uint32_t>((count + RS_VIS_TILES_PER_ROW - 1) / RS_VIS_TILES_PER_ROW);
  const uint32_t width = columns * RS_VIS_TILE, height = rows * RS_VIS_TILE;
  drawIntoAtlas(d, gpu, materials, positions, nullptr, farDistance, reach, cull,
                std::vector<float>(static_cast<size_t>(width) * height * 2, 0.0f), width, height, vis);
  vis.builtFor = positions;
  vis.builtReach = reach;
  return true;
}

void destroyProbeVisibility(VulkanDevice& d, ProbeVisibility& vis) {
  destroyOwned(d, vis);
  if (vis.cutoutPipeline) vkDestroyPipeline(d.device, vis.cutoutPipeline, nullptr);
  if (vis.pipeline) vkDestroyPipeline(d.device, vis.pipeline, nullptr);
  if (vis.layout) vkDestroyPipelineLayout(d.device, vis.layout, nullptr);
  vis = ProbeVisibility{};
}

}  // namespace probecast::renderer
