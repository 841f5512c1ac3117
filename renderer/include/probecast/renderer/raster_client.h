// The raster client: renders views of a scene with direct light from its punctual lights (shadow
// maps with PCF), surface emission, diffuse indirect light albedo/π · E(n) and split-sum glossy
// indirect light from a probe volume (SH in 3D textures). With visibility on, each point blends the
// 8 probes of its cell weighted by trilinear × backface × Chebyshev visibility from per-probe
// distance moments that the client makes from its own geometry (probe_visibility.h), so probes
// behind walls or inside boxes do not light it; off, hardware trilinear filtering weighted by probe
// activity (probes inside walls never darken their active neighbours; inactive probes are also
// filled from active neighbours for places no active probe reaches). Offscreen, dynamic
// rendering, linear radiance out. A view set renders with its shadow maps drawn once, in chunks
// of views: one pass per view, or one multiview pass per chunk. Pixels no surface covers show the
// environment (black without one).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/codec/probe_volume.h"
#include "probecast/renderer/environment.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/area_lights.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

enum class ViewPasses {
  PerView,    // one render pass per view (views of a chunk share one submission)
  Multiview,  // one multiview pass per chunk of views (VK_KHR_multiview, gl_ViewIndex)
};

struct RasterOptions {
  uint32_t shadowMapSize = 1024;  // texels per side of each shadow layer
  uint32_t maxShadowLayers = 24;  // point lights take 6, spot lights 1, directional ones
                                  // shadowCascades (or what is left, at least 1); lights past
                                  // the budget (in scene order) are lit unshadowed
  // Orthographic layers per directional light (1..4): 1 covers the whole scene; more are cascades
  // fitted to slices of each view set's depth range (the union of its views' frusta), finest first.
  uint32_t shadowCascades = 4;
  ViewPasses passes = ViewPasses::PerView;
  // Emitters shaded per pixel as area lights with soft shadows (area_lights.h). Give the probe
  // updater the same options (UpdaterOptions::areaLights), so the probes leave that light out.
  scene::AreaLightOptions areaLights;
  uint32_t areaShadowMapSize = 512;  // texels per side of each area light's shadow layer
  // Drawn as background where no surface covers a pixel (linear radiance like the rest, so the
  // same exposure and tone map apply); its light reaches surfaces through the probes only.
  std::shared_ptr<const Environment> environment;
  // Probe visibility (depth moments per probe, made by setProbes when the probe positions change);
  // off: hardware trilinear over active probes, as before visibility existed.
  bool visibility = true;
  // Each probe's depth cube sees as far as visibilityReach × its reach (1.5 cell diagonals + a
  // quarter of the smallest spacing): distances are clamped there and farther triangles are not
  // drawn. 0: no limit (every face draws the whole scene, as before the limit existed).
  float visibilityReach = 1.0f;
  // Off: every face draws every triangle (the same moments, slower; to compare and measure).
  bool visibilityCulling = true;
  // Raster samples per pixel side (1..16): views are drawn at this multiple of the size and each
  // pixel is the mean of its N × N block, the footprint a path-traced reference averages. Costs
  // about N² the shading time; the images keep the size the renderer was made with. 1 by default.
  uint32_t samplesPerSide = 1;
  // Multisample anti-aliasing: 1 (off), 2, 4 or 8 coverage samples per target pixel, shaded once
  // per pixel and resolved by averaging (the device must offer the count for RGBA32F colour and
  // D32 depth, as Vulkan requires of 4; std::invalid_argument otherwise); combines with
  // samplesPerSide. 4 by default, the measured best: within 0.1 dB of 4 × 4 supersampling against
  // a path-traced reference on the untextured Cornell box, 0.45 dB on the textured Sponza (with
  // mip-mapped textures, below), at a tenth to a third of its cost (docs/MEASUREMENTS.md,
  // "Anti-aliasing").
  uint32_t msaaSamples = 4;
  // Textures are read over each pixel's footprint from their mip levels (trilinear); a footprint
  // stretched along one axis takes up to this many taps along it (1..16; 1: isotropic, blurred
  // where surfaces are seen at a grazing angle).
  uint32_t anisotropy = 8;
};

struct RasterTimings {
  double shadowMs = 0.0;  // last shadow-map pass
  double areaShadowMs = 0.0;  // last area-light shadow-map pass
  uint32_t shadowLayersDrawn = 0, areaShadowLayersDrawn = 0;  // by the last renderViews (0: all kept)
  double viewsMs = 0.0;   // last renderViews, shadows excluded, readback included
  double visibilityRenderMs = 0.0;   // last visibility build: depth cubes drawn and read back
  double visibilityMomentsMs = 0.0;  // last visibility build: moments on the CPU and their upload
  uint64_t visibilityTriangles = 0;  // last visibility build: triangles drawn over all cube faces
  uint64_t geometryMoves = 0;        // setShading calls that moved vertices
  uint32_t visibilityProbesRedrawn = 0;  // the last move: probes whose depth cubes were drawn again
};

// Throws std::invalid_argument unless views of width × height at options.samplesPerSide fit a
// raster target (1..16 samples per side, at most 16384 pixels a side), msaaSamples is 1, 2, 4 or 8
// and anisotropy 1..16: to refuse before slow work.
void checkRasterSize(uint32_t width, uint32_t height, const RasterOptions& options);

// Replaces inactive probes by the mean of their active neighbours, growing outwards until every
// probe has a value (so trilinear filtering never blends in zeros from inside walls).
void fillInactiveProbes(ProbeVolume& volume);

class RasterRenderer {
 public:
  // Images of width × height; the targets are samplesPerSide times larger, at most 16384 a side
  // (std::invalid_argument otherwise).
  RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height,
                 const RasterOptions& options = {});
  ~RasterRenderer();
  RasterRenderer(const RasterRenderer&) = delete;
  RasterRenderer& operator=(const RasterRenderer&) = delete;

  // Uploads a volume (checkProbeVolume's rules) into 3D textures kept across updates (re-created
  // only when the grid's size changes). zh3PerPixel: the shader hallucinates ZH3 after
  // interpolating; zh3 is expected expanded to SH3 already (as the codec decodes it).
  // Throws std::invalid_argument (and keeps the previous volume) for a volume that fails the check,
  // or whose offsets are neither empty nor 3 finite floats per probe. With visibility on, the
  // moments are made again when the probe positions (grid + offsets) differ from the last ones;
  // a volume of more than visibilityMaxProbes() probes is drawn without visibility.
  void setProbes(const ProbeVolume& volume);
  // Whether the current volume is drawn with visibility.
  bool visibilityActive() const;
  // Client memory per probe for visibility (moments tile and position), bytes; and the most probes.
  static uint32_t visibilityBytesPerProbe();
  static uint32_t visibilityMaxProbes();
  // Texels per side of each probe's octahedral moment map (without its border).
  static uint32_t visibilityMapTexels();
  // The host copy of a probe's moments (E[r], E[r²]) toward `dir`, metres (nearest texel).
  glm::vec2 probeMoments(uint32_t probe, const glm::vec3& dir) const;
  // The same triangles with new positions, lights, materials, normals, texture coordinates or
  // textures (an animated scene): shadows are redrawn, and the visibility of the probes within
  // reach of a moved triangle is drawn again at once (the others keep theirs).
  void setShading(const scene::Scene& scene);
  // The same, with client area lights by other options (those a stream's probes were made with:
  // RasterOptions::areaLights from now on).
  void setAreaLights(const scene::Scene& scene, const scene::AreaLightOptions& options);
  // Renders a view set; images in the order of `views`.
  std::vector<Image> renderViews(const std::vector<ViewInfo>& views);
  // Renders one view; `viewProj` maps world to Vulkan clip space (y down, z in [0, 1]).
  Image render(const glm::mat4& viewProj, const glm::vec3& eye);
  // Draws the next view sets at `scale` × the image size on each side (at least a pixel; 1, the
  // default: full size), in a corner of the same targets, so that a device too slow for the full
  // size holds a frame rate (the live window's dynamic resolution). The images come out that size.
  // Throws std::invalid_argument for a scale outside (0, 1] (NaN included).
  void setRenderScale(float scale);
  float renderScale() const;
  // Views per chunk (multiview: the device's limit, at most 8).
  uint32_t chunkSize() const;
  const RasterTimings& timings() const;
  // The client area lights in use (empty when RasterOptions::areaLights is off).
  const scene::AreaLightSet& areaLights() const;
  // A perspective view-projection for a camera (Vulkan conventions) at the target's aspect.
  glm::mat4 viewProjection(const CameraView& camera) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::renderer
