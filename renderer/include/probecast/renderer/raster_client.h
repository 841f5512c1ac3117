// The raster client: renders views of a scene with direct light from its punctual lights (shadow
// maps with PCF), surface emission, diffuse indirect light albedo/π · E(n) and split-sum glossy
// indirect light from a probe volume (SH in 3D textures, hardware trilinear filtering weighted by
// probe activity, so probes inside walls never darken their active neighbours; inactive probes are
// also filled from active neighbours for places no active probe reaches). Offscreen, dynamic
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
  uint32_t maxShadowLayers = 24;  // point lights take 6, spot and directional lights 1; lights past
                                  // the budget (in scene order) are lit unshadowed
  ViewPasses passes = ViewPasses::PerView;
  // Emitters shaded per pixel as area lights with soft shadows (area_lights.h). Give the probe
  // updater the same options (UpdaterOptions::areaLights), so the probes leave that light out.
  scene::AreaLightOptions areaLights;
  uint32_t areaShadowMapSize = 512;  // texels per side of each area light's shadow layer
  // Drawn as background where no surface covers a pixel (linear radiance like the rest, so the
  // same exposure and tone map apply); its light reaches surfaces through the probes only.
  std::shared_ptr<const Environment> environment;
};

struct RasterTimings {
  double shadowMs = 0.0;  // last shadow-map pass
  double areaShadowMs = 0.0;  // last area-light shadow-map pass
  double viewsMs = 0.0;   // last renderViews, shadows excluded, readback included
};

// Replaces inactive probes by the mean of their active neighbours, growing outwards until every
// probe has a value (so trilinear filtering never blends in zeros from inside walls).
void fillInactiveProbes(ProbeVolume& volume);

class RasterRenderer {
 public:
  RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height,
                 const RasterOptions& options = {});
  ~RasterRenderer();
  RasterRenderer(const RasterRenderer&) = delete;
  RasterRenderer& operator=(const RasterRenderer&) = delete;

  // Uploads a volume (checkProbeVolume's rules) into 3D textures kept across updates (re-created
  // only when the grid's size changes). zh3PerPixel: the shader hallucinates ZH3 after
  // interpolating; zh3 is expected expanded to SH3 already (as the codec decodes it).
  // Throws std::invalid_argument (and keeps the previous volume) for a volume that fails the check.
  void setProbes(const ProbeVolume& volume);
  // The same geometry with new lights or materials (an animated scene); shadows are redrawn.
  void setShading(const scene::Scene& scene);
  // Renders a view set; images in the order of `views`.
  std::vector<Image> renderViews(const std::vector<ViewInfo>& views);
  // Renders one view; `viewProj` maps world to Vulkan clip space (y down, z in [0, 1]).
  Image render(const glm::mat4& viewProj, const glm::vec3& eye);
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
