// The raster client: renders views of a scene with direct light from its punctual lights, surface
// emission, and diffuse indirect light albedo/π · E(n) from a probe volume (L2 SH in 3D textures,
// hardware trilinear filtering; inactive probes are filled from active neighbours so they never
// darken them). Offscreen, dynamic rendering, linear radiance out.
//
// Not yet: shadow maps (direct light is unshadowed), glossy indirect (glossy_sh.h holds its math),
// multi-view passes and quilts.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

struct ProbeVolumeData {
  glm::uvec3 dims{0};
  glm::vec3 min{0.0f};            // position of probe (0,0,0), metres
  glm::vec3 max{0.0f};            // position of the last probe
  std::vector<float> probes;      // 27 floats per probe, sh.h layout (radiance)
  std::vector<uint8_t> active;    // 1 = active; empty = all active
};

// Replaces inactive probes by the mean of their active neighbours, growing outwards until every
// probe has a value (so trilinear filtering never blends in zeros from inside walls).
void fillInactiveProbes(ProbeVolumeData& volume);

class RasterRenderer {
 public:
  RasterRenderer(VulkanContext& context, const scene::Scene& scene, uint32_t width, uint32_t height);
  ~RasterRenderer();
  RasterRenderer(const RasterRenderer&) = delete;
  RasterRenderer& operator=(const RasterRenderer&) = delete;

  void setProbes(const ProbeVolumeData& volume);
  // Renders one view; `viewProj` maps world to Vulkan clip space (y down, z in [0, 1]).
  Image render(const glm::mat4& viewProj, const glm::vec3& eye);
  // A perspective view-projection for a camera (Vulkan conventions) at the target's aspect.
  glm::mat4 viewProjection(const CameraView& camera) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::renderer
