// The image harness: path-traced references cached on disk, each with its own noise floor, and
// the one way benches compare a render against them.
//
// A reference of N samples per pixel is two independent half-references of N/2 samples (seeds
// `seed` and `seed + kSecondSeedOffset`). Their mean is the reference; their difference measures
// its noise. With σ² the per-pixel variance of one half:
//   MSE(A, B)          = 2σ²     → the noise floor, PSNR(A, B)
//   MSE(mean, truth)   = σ² / 2  → the reference's own accuracy, PSNR(A, B) + 10·log10(4) ≈ floor + 6.02 dB
// A render whose PSNR against the reference comes near that second figure is as close as the
// reference can tell (the measured MSE is the true one plus σ²/2). Both are quoted beside every
// PSNR. (PSNR is taken after gamma 2.2; for small noise the gamma curve is locally linear and the
// 6 dB relation holds to first order.)
//
// Cache entries live in a directory (default $XDG_CACHE_HOME/probecast/references, else
// ~/.cache/probecast/references) as KEY.json (a summary: key, spp, seconds) and per half KEY.a.exr +
// KEY.a.json, KEY.b.exr + KEY.b.json, each half stored as soon as it is traced (an interrupted run
// keeps the half it finished). KEY is a hash of everything
// that changes the picture: the scene's loaded content (geometry, materials, textures, lights,
// cameras), the animation time, the camera, size, samples, seed, bounces, the environment's
// pixels (intensity applied) and rotation, and kReferenceRendererVersion. Each half's JSON repeats
// the key in full, its seed and samples, and the hash of its image's pixels, so a stale, mismatched
// or damaged half is found and rendered again, never used.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/imaging/image_metrics.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"

namespace probecast::bench {

// Raise when the reference tracer's picture changes for the same inputs (it invalidates every entry).
constexpr int kReferenceRendererVersion = 1;
constexpr uint32_t kSecondSeedOffset = 0x9e3779b9u;

// What a reference shows: the scene at time t seen by `camera`; the tracer's options (width,
// height, samplesPerPixel in total over both halves, maxBounces, seed, environment...).
struct ReferenceRequest {
  float t = 0.0f;
  renderer::CameraView camera;
  renderer::ReferenceOptions options;  // `progress` is ignored: the cache reports its own
};

struct Reference {
  renderer::Image mean;              // the reference used for comparisons
  renderer::Image halfA, halfB;      // the two seeds
  imaging::ImageMetrics floor;       // half A against half B
  double accuracyDb = 0.0;           // estimated PSNR of `mean` against the truth: floor + 10·log10(4)
  double seconds = 0.0;              // tracing time of both halves (when it was rendered)
  bool fromCache = false;
  std::string key;                   // the entry's file stem
};

// The reference of `camera`'s view at t: `width`×`height`, `spp` samples per pixel over both
// halves, lit by `environment` (none: misses are black); the tracer's other options as they default.
ReferenceRequest referenceRequest(const renderer::CameraView& camera, uint32_t width, uint32_t height, uint32_t spp,
                                  std::shared_ptr<const renderer::Environment> environment, float t = 0.0f);

// The key in full (JSON) and its file stem (16 hex digits of its hash).
nlohmann::json referenceKey(const scene::Scene& scene, const ReferenceRequest& request);
std::string referenceKeyStem(const nlohmann::json& key);
// Writes `bytes` under a temporary name, then renames it into place: a reader sees all or nothing.
// Throws std::runtime_error naming the file when either fails.
void writeFileAtomically(const std::string& path, const std::string& bytes);
// A 64-bit hash of the loaded scene's content, as 16 hex digits.
std::string sceneContentHash(const scene::Scene& scene);
// The same hash of an image's float pixels (a reference half's, checked when read back).
std::string pixelHash(const std::vector<float>& rgb);
// $XDG_CACHE_HOME/probecast/references, else $HOME/.cache/probecast/references.
std::string defaultReferenceCacheDir();

class ReferenceCache {
 public:
  ReferenceCache(renderer::VulkanContext& context, std::string dir,
                 std::function<void(const std::string&)> progress = nullptr);
  // The cached reference, or a new one rendered and stored. Throws std::runtime_error when the
  // directory cannot be written, or the request is unusable (fewer than 2 samples per pixel).
  Reference get(const scene::Scene& scene, const ReferenceRequest& request);
  // Half-references traced by this cache so far (two per reference rendered from nothing).
  uint32_t renders() const { return renders_; }
  const std::string& dir() const { return dir_; }

 private:
  bool loadHalf(const nlohmann::json& key, const std::string& stem, int k, uint32_t seed, uint32_t spp,
                renderer::Image& out, double& seconds, std::string& why) const;
  // Traces half `k` (seed `seed`, `spp` samples per pixel) and stores it, its JSON last; `out` is
  // what a later run will load. Returns the tracing seconds; `pixels` is the image's hash.
  double renderHalf(const scene::Scene& scene, const ReferenceRequest& request, const nlohmann::json& key,
                    const std::string& stem, int k, uint32_t seed, uint32_t spp, renderer::Image& out,
                    std::string& pixels);
  renderer::VulkanContext& context_;
  std::string dir_;
  std::function<void(const std::string&)> progress_;
  uint32_t renders_ = 0;
};

// Raster options for the benches that compare streams, representations or rules rather than
// anti-aliasing: one raster sample per pixel, so their figures hold when the viewers' default
// (RasterOptions::samplesPerSide, msaaSamples) moves. bench scene and bench raster take --supersample.
inline renderer::RasterOptions singleSampleRaster() {
  renderer::RasterOptions o;
  o.samplesPerSide = 1;
  o.msaaSamples = 1;
  return o;
}

// A bench's progress line, sent where `progress` says (nowhere when it is empty).
void sayProgress(const std::function<void(const std::string&)>& progress, const std::string& line);
// Milliseconds of the steady clock since `start`.
double millisecondsSince(std::chrono::steady_clock::time_point start);

// An image against the reference and against a second image of the same view (the float-probe
// render, isolating the codec's loss). Throws std::invalid_argument naming `what` when an image
// holds non-finite pixels or the sizes differ.
struct Comparison {
  imaging::ImageMetrics vsReference;
  imaging::ImageMetrics vsFloat;
};
imaging::ImageMetrics compareChecked(const renderer::Image& image, const renderer::Image& reference,
                                     const std::string& what);
Comparison compareView(const renderer::Image& image, const Reference& reference, const renderer::Image& floatRender,
                       const std::string& what);
// "floor 38.21 dB, reference ≈ 44.23 dB": what to print beside a PSNR against `reference`.
std::string describeFloor(const Reference& reference);

}  // namespace probecast::bench
