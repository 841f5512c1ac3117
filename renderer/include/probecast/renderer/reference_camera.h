// Ground truth: a camera path tracer with the probe updater's materials, lights and path loop
// (emission, next-event estimation, Lambert + GGX, Russian roulette), many samples per pixel.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/renderer/environment.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

struct CameraView {
  glm::vec3 position{0.0f, 1.0f, 3.9f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float yfov = 0.6911f;  // radians
  // Off-axis (sheared) frustum: the image centre on the plane one metre ahead, in metres along
  // right and up. Zero for an ordinary centred camera.
  glm::vec2 shift{0.0f};
  // The scene's first camera, or a view of its bounds from +Z when it has none.
  static CameraView fromScene(const scene::Scene& s);
};

struct ReferenceOptions {
  uint32_t width = 320;
  uint32_t height = 240;
  uint32_t samplesPerPixel = 256;
  uint32_t maxBounces = 8;
  uint32_t seed = 1;
  float indirectClamp = 0.0f;  // off: the reference is unbiased
  std::shared_ptr<const Environment> environment;  // none: misses are black
  bool environmentSampling = true;  // false: reach the environment by BSDF sampling only
  std::function<void(uint32_t done, uint32_t total)> progress;  // samples per pixel done
};

struct Image {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<float> rgb;  // linear radiance, row-major from the top
};

struct ReferenceStats {
  uint64_t samples = 0;         // path samples traced (pixels × spp)
  uint64_t droppedSamples = 0;  // non-finite samples left out of their pixel's mean (a defect if nonzero)
};

// Each pixel is the mean of its finite samples; `stats` (optional) counts the rest.
Image renderReference(VulkanContext& context, const scene::Scene& scene, const CameraView& camera,
                      const ReferenceOptions& options, ReferenceStats* stats = nullptr);

}  // namespace probecast::renderer
