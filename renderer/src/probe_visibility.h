// Probe visibility for the raster client, made from the client's own geometry (no ray tracing, no
// wire bytes): a low-resolution depth cube is rasterised from every probe position (six 90° faces,
// all probes of a batch in one depth atlas, one render pass), read back, and turned on the CPU into
// an octahedral map of distance moments (E[r], E[r²]) per probe, each texel the mean over a
// cosine-power lobe around its direction (as DDGI filters its depth). raster.frag weighs each of
// the 8 probes around a point by a Chebyshev bound on the probability that the point is visible
// from the probe. Made again only when the probe positions change (a new grid, new offsets).
//
// Each probe sees only as far as its reach (probeVisibilityReach): distances are clamped to it (as
// DDGI clamps its depth), open directions included, and raster.frag tests a point beyond it as if
// at it, so the triangles wholly beyond it change nothing and are not drawn. The scene's triangles
// are cut into clusters of consecutive ones (finalizeScene orders each material class by the Morton
// code of the centroids, so a run is a compact piece of the scene), each with its bounds; each face
// of each cube keeps the clusters whose bounds meet both the reach sphere and the face's 90°
// pyramid, then, of the opaque ones, each triangle whose own box does, gathered into one index list
// drawn with one call per face. Cut-out (alphaMode Mask) triangles are drawn by runs of clusters
// through shadow.frag, which finds each one's material by its number, so what is cut away does
// not block.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gpu_scene.h"
#include "probecast/codec/probe_volume.h"
#include "raster_shared.h"
#include "vk_resources.h"

namespace probecast::renderer {

constexpr uint32_t kVisibilityCubeSize = 32;       // texels per side of each depth-cube face
constexpr uint32_t kMaxVisibilityProbes = 1u << 16;  // larger volumes are drawn without visibility
constexpr float kVisibilityLobePower = 50.0f;        // cos^k lobe of each moment texel (DDGI's depth sharpness)
// Client memory per probe: the atlas tile, two 32-bit floats per texel, plus its position (vec4).
constexpr uint32_t kVisibilityBytesPerProbe = RS_VIS_TILE * RS_VIS_TILE * 8 + 16;

// Triangles [first, first + count) of the scene's order, and their bounds.
struct VisibilityCluster {
  uint32_t first = 0, count = 0;
  glm::vec3 lo{0.0f}, hi{0.0f};
};

struct ProbeVisibility {
  GpuImage moments;                // RG32F atlas (raster_shared.h's layout), sampled by raster.frag
  Buffer positions;                // vec4 per probe: the moved position and the reach, metres
  std::vector<float> atlas;        // host copy of `moments`, 2 floats per texel
  uint32_t atlasWidth = 0, atlasHeight = 0;
  std::vector<float> builtFor;     // xyz per probe of the last build (skips unchanged positions)
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;        // opaque triangles: depth only, no bias
  VkPipeline cutoutPipeline = VK_NULL_HANDLE;  // cut-outs: shadow.frag discards what is cut away
  std::vector<VisibilityCluster> opaque;       // clusters of `proxy`'s triangles (numbers in it)
  // The opaque triangles the depth cubes draw, scene vertex numbers three per triangle: the still
  // ones simplified (meshoptimizer) to proxyError metres, about a cube texel where probes look
  // (kVisibilityProxyError of the reach), the moving ones as they are.
  std::vector<uint32_t> proxy;
  float proxyError = -1.0f;                     // of `proxy` (< 0: none made yet)
  std::vector<uint32_t> opaqueIndices;          // the scene's opaque triangles (its order)
  std::vector<uint8_t> opaqueMoving;            // per opaque triangle: it moves with the scene clock
  std::vector<glm::vec3> vertices;              // the scene's vertices now
  std::vector<glm::vec3> proxyFrom;             // and when `proxy` was made
  std::vector<VisibilityCluster> cutouts;      // clusters of the cut-out (alphaMode Mask) ones
  float builtReach = 0.0f;                     // reach of the last build
  double renderMs = 0.0, momentsMs = 0.0;  // last build: depth cubes drawn and read back; moments + upload
  uint64_t trianglesDrawn = 0;             // last build: triangles drawn over every cube face
};

constexpr uint32_t kVisibilityClusterTriangles = 16;  // most triangles per cluster
// The still geometry's simplification error, as a fraction of the probes' reach: 1.5 % (7.5 cm in
// Sponza's 16×8×8 grid, where a cube texel a metre away is 6 cm; its views then differ from those
// of the exact geometry by 55 dB PSNR, and the build draws 0.75 M triangles instead of 6.6 M).
constexpr float kVisibilityProxyError = 0.015f;

// `materials`: the raster client's set layout (the depth pass binds none of it, the layout is shared).
// Starts with one probe at the origin and an empty map (every direction open), so descriptors are valid.
void createProbeVisibility(VulkanDevice& d, VkDescriptorSetLayout materials, ProbeVisibility& out);
// Cuts the opaque and cut-out triangles of `scene` (as uploaded to the GpuScene the builds draw)
// into clusters.
// `keepBuilt`: the same triangles moved, and redrawProbeVisibility follows; otherwise the next
// build draws every probe again.
void setProbeVisibilityScene(const scene::Scene& scene, ProbeVisibility& vis, bool keepBuilt = false);
// How far a probe of `grid` needs to see: 1.5 cell diagonals (a probe moved by at most half its cell
// per axis weighs points of the 8 cells around its grid point, each within one diagonal of it, so
// within 1.5 of the probe) plus 0.25 of the smallest spacing (raster.frag moves the point 0.225 ×
// that off the surface). An axis with one probe counts `sceneExtent` on that axis as its cell.
float probeVisibilityReach(const ProbeGrid& grid, const glm::vec3& sceneExtent);
// Rasterises depth cubes of the opaque and cut-out triangles of `gpu` from `positions` (xyz per
// probe) and rebuilds the moments; `materials`: the raster client's set (cut-outs read their
// material). `farDistance` is what an open direction reads, and so does any surface farther than
// `reach` (infinity: no limit). `cull`: draw only the clusters within reach of each face (off: every
// triangle, the same moments). Returns false (and does nothing) when the positions and reach equal
// those of the last build. Throws std::invalid_argument for more than kMaxVisibilityProbes probes.
// New images replace the old only once made.
bool buildProbeVisibility(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials,
                          const std::vector<float>& positions, float farDistance, float reach, bool cull,
                          ProbeVisibility& vis);
// After moved geometry (setProbeVisibilityScene with keepBuilt): the probes of the last build
// within `reach` of the box around a moved triangle's old and new corners (`before`, `after`:
// positions of the same triangles `indices`). Every probe when the reach is unlimited.
std::vector<uint32_t> probesNearMovedGeometry(const ProbeVisibility& vis, const std::vector<glm::vec3>& before,
                                              const std::vector<glm::vec3>& after,
                                              const std::vector<uint32_t>& indices);
// Draws the depth cubes of the probes `which` (indices into the last build's positions) again and
// replaces their tiles of the moments, with the last build's reach; the other probes keep theirs
// (nothing within their reach moved). Needs a build before; returns the number of probes drawn.
uint32_t redrawProbeVisibility(VulkanDevice& d, const GpuScene& gpu, VkDescriptorSet materials,
                               const std::vector<uint32_t>& which, float farDistance, bool cull, ProbeVisibility& vis);
void destroyProbeVisibility(VulkanDevice& d, ProbeVisibility& vis);

// The moments of one probe from its depth cube (6 faces of `size`² distances, face order +x −x +y
// −y +z −z as `cubeFaceViews`): RS_VIS_TILE² texels × 2 floats into `tile`, borders included.
void octahedralMoments(const float* cubeDistances, uint32_t size, float* tile);
// The unit direction through the centre of texel (x, y) of face `face` of a depth cube `size`
// texels a side, as the cubes are drawn (faces +x −x +y −y +z −z, rows as the depth image's).
glm::vec3 cubeTexelDirection(uint32_t face, uint32_t x, uint32_t y, uint32_t size);
// (E[r], E[r²]) of `probe` toward `dir` from the host copy, at the nearest texel.
glm::vec2 probeMomentsAt(const ProbeVisibility& vis, uint32_t probe, const glm::vec3& dir);

// Octahedral mapping of unit directions to [-1, 1]² and back (the same formulas as raster.frag).
glm::vec2 octEncode(const glm::vec3& dir);
glm::vec3 octDecode(glm::vec2 e);

}  // namespace probecast::renderer
