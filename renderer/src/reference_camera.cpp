#include "probecast/renderer/reference_camera.h"

#include <algorithm>
#include <cmath>

#include "gpu_scene.h"
#include "reference_camera.rgen.h"
#include "vk_raytracing.h"

namespace probecast::renderer {

CameraView CameraView::fromScene(const scene::Scene& s) {
  CameraView v;
  if (!s.cameras.empty()) {
    const scene::Camera& c = s.cameras.front();
    v.position = c.position;
    v.forward = c.forward;
    v.up = c.up;
    v.yfov = c.yfov;
    return v;
  }
  const glm::vec3 centre = 0.5f * (s.boundsMin + s.boundsMax);
  const float radius = 0.5f * glm::length(s.boundsMax - s.boundsMin);
  v.position = centre + glm::vec3(0.0f, 0.0f, radius / std::tan(0.5f * v.yfov) + radius);
  return v;
}

Image renderReference(VulkanContext& context, const scene::Scene& scene, const CameraView& camera,
                      const ReferenceOptions& options, ReferenceStats* stats) {
  requireRayTracing(context.device(), "the reference renderer");
  if (scene.triangleCount() == 0) throw std::invalid_argument("scene " + scene.name + " has no triangles");
  if (options.width == 0 || options.height == 0 || options.samplesPerPixel == 0)
    throw std::invalid_argument("reference image needs a size and samples");
  VulkanDevice& d = context.device();
  GpuScene gpu;
  RayTracingPass pass;
  const size_t pixels = static_cast<size_t>(options.width) * options.height;
  Buffer accumulation = createBuffer(d, pixels * 4 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Buffer unused = createBuffer(d, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Image image;
  try {
    uploadGpuScene(d, scene, gpu);
    uploadGpuEnvironment(d, options.environment.get(), options.environmentSampling, gpu);
    createRayTracingPass(d, kReferenceCameraRgen, sizeof kReferenceCameraRgen, sizeof(shaders::PtCameraPushConstants),
                         pass);
    std::fill_n(static_cast<float*>(accumulation.mapped), pixels * 4, 0.0f);
    const glm::vec3 f = glm::normalize(camera.forward);
    const glm::vec3 r = glm::normalize(glm::cross(f, camera.up));
    const glm::vec3 u = glm::cross(r, f);
    shaders::PtCameraPushConstants push{};
    push.position = {camera.position.x, camera.position.y, camera.position.z, 1.0f};
    push.forward = {f.x, f.y, f.z, std::tan(0.5f * camera.yfov)};
    push.right = {r.x, r.y, r.z, static_cast<float>(options.width) / static_cast<float>(options.height)};
    push.up = {u.x, u.y, u.z, 0.0f};
    push.shiftRight = camera.shift.x;
    push.shiftUp = camera.shift.y;
    push.width = options.width;
    push.height = options.height;
    push.seed = options.seed;
    push.lightCount = gpu.lightCount;
    push.emitterCount = gpu.emitterCount;
    push.emitterPower = gpu.emitterPower;
    push.maxBounces = std::clamp<uint32_t>(options.maxBounces, 1, PT_MAX_BOUNCES_LIMIT);
    push.indirectClamp = options.indirectClamp;
    // Dispatches of bounded size keep each submission short (and a GPU watchdog happy).
    const uint32_t perDispatch = std::max<uint32_t>(1, static_cast<uint32_t>(4'000'000 / std::max<size_t>(pixels, 1)));
    uint32_t done = 0;
    for (uint32_t k = 0; done < options.samplesPerPixel; ++k) {
      push.samplesPerPixel = std::min(perDispatch, options.samplesPerPixel - done);
      push.dispatchIndex = k;
      const RayTracingInputs in{&gpu, &unused, &unused, &accumulation};
      runRayTracingPass(d, pass, in, &push, options.width, options.height);
      done += push.samplesPerPixel;
      if (options.progress) options.progress(done, options.samplesPerPixel);
    }
    image.width = options.width;
    image.height = options.height;
    image.rgb.resize(pixels * 3);
    const float* acc = static_cast<const float*>(accumulation.mapped);
    uint64_t kept = 0;
    for (size_t i = 0; i < pixels; ++i) {
      kept += static_cast<uint64_t>(acc[i * 4 + 3]);  // exact: counts stay far below 2^24
      for (int c = 0; c < 3; ++c) image.rgb[i * 3 + c] = acc[i * 4 + 3] > 0 ? acc[i * 4 + c] / acc[i * 4 + 3] : 0.0f;
    }
    if (stats) {
      stats->samples = static_cast<uint64_t>(pixels) * options.samplesPerPixel;
      stats->droppedSamples = stats->samples - std::min(kept, stats->samples);
    }
  } catch (...) {
    destroyRayTracingPass(d, pass);
    destroyGpuScene(d, gpu);
    destroyBuffer(d, accumulation);
    destroyBuffer(d, unused);
    throw;
  }
  destroyRayTracingPass(d, pass);
  destroyGpuScene(d, gpu);
  destroyBuffer(d, accumulation);
  destroyBuffer(d, unused);
  return image;
}

}  // namespace probecast::renderer
