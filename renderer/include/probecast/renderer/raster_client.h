// The raster client: renders views of a scene with direct light from its punctual lights (shadow
// maps with PCF), surface emission, diffuse indirect light albedo/π · E(n) and split-sum glossy
// indirect light from a probe volume (SH in 3D textures, hardware trilinear filtering weighted by
// probe activity, so probes inside walls never darken their active neighbours; inactive probes are
// also filled from active neighbours for places no active probe reaches). Offscreen, dynamic
// rendering, linear radiance out. A view set renders with its shadow maps drawn once, in chunks
// of views: one pass per view, or one multiview pass per chunk.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/codec/record.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

struct ProbeVolumeData {
  glm::uvec3 dims{0};
  glm::vec3 min{0.0f};            // position of probe (0,0,0), metres
  glm::vec3 max{0.0f};            // position of the last probe
  std::vector<float> probes;      // 27 floats per probe, sh.h layout (radiance)
  std::vector<uint8_t> active;    // 1 = active; empty = all active
  // zh3h decoded without hallucination: the L2 band is empty and the shader hallucinates ZH3 per
  // pixel from the interpolated L1 (interpolate, then hallucinate).
  bool hallucinateZh3 = false;
};

class ProbeUpdater;
// The updater's current probes and active mask as a volume.
ProbeVolumeData volumeFromUpdater(const ProbeUpdater& updater);

// The volume as a viewer holds it after the codec: every probe through a `repr` record and back.
// zh3h decodes L1 only and sets hallucinateZh3; zh3 expands to SH3 here, before upload.
ProbeVolumeData decodeAs(const ProbeVolumeData& volume, Representation repr);

enum class ViewPasses {
  PerView,    // one render pass per view (views of a chunk share one submission)
  Multiview,  // one multiview pass per chunk of views (VK_KHR_multiview, gl_ViewIndex)
};

struct RasterOptions {
  uint32_t shadowMapSize = 1024;  // texels per side of each shadow layer
  uint32_t maxShadowLayers = 24;  // point lights take 6, spot and directional lights 1; lights past
                                  // the budget (in scene order) are lit unshadowed
  ViewPasses passes = ViewPasses::PerView;
};

struct RasterTimings {
  double shadowMs = 0.0;  // last shadow-map pass
  double viewsMs = 0.0;   // last renderViews, shadows excluded, readback included
};

// Replaces inactive probes by the mean of their active neighbours, growing outwards until every
// probe has a value (so trilinear filtering never blends in zeros from inside walls).
void fillInactiveProbes(ProbeVolumeData& volume);

class RasterRenderer {
 public:
  RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height,
                 const RasterOptions& options = {});
  ~RasterRenderer();
  RasterRenderer(const RasterRenderer&) = delete;
  RasterRenderer& operator=(const RasterRenderer&) = delete;

  // Throws std::invalid_argument (and keeps the previous volume) for a volume whose size, mask or
  // bounds do not add up, or that holds a non-finite coefficient.
  void setProbes(const ProbeVolumeData& volume);
  // The same geometry with new lights or materials (an animated scene); shadows are redrawn.
  void setShading(const scene::Scene& scene);
  // Renders a view set; images in the order of `views`.
  std::vector<Image> renderViews(const std::vector<ViewInfo>& views);
  // Renders one view; `viewProj` maps world to Vulkan clip space (y down, z in [0, 1]).
  Image render(const glm::mat4& viewProj, const glm::vec3& eye);
  // Views per chunk (multiview: the device's limit, at most 8).
  uint32_t chunkSize() const;
  const RasterTimings& timings() const;
  // A perspective view-projection for a camera (Vulkan conventions) at the target's aspect.
  glm::mat4 viewProjection(const CameraView& camera) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::renderer
