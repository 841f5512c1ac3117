// The parts of `probecast bench adaptive` (adaptive_bench.h) that its files share: what every
// phase works with (the Setup, the converged Truth), one rule's run through the phases with its
// streams, and the report of them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/codec/stream.h"
#include "probecast/imaging/image_metrics.h"
#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/scene_loading.h"
#include "adaptive_bench.h"
#include "harness.h"
#include "stability.h"

namespace probecast::bench::adaptive {

// One stream a rule's volumes go through: what it cost per frame, and what it holds.
struct Stream {
  std::string name;
  EncoderOptions options;
  bool withNoise = false;
  float oracleRatio = 0.0f;  // > 0: the oracle stream (oracleSelect)
  float oracleExponent = 0.0f;
  std::vector<float> viewWeights;  // StreamEncoder::setViewWeights (empty: none)
  std::unique_ptr<StreamEncoder> encoder;
  std::vector<double> bytesPerProbe;  // per frame
  std::vector<float> held;            // what a subscriber holds after the frame before
  std::vector<double> heldChanges;    // per frame: its relative irradiance change (what a viewer sees flicker)
  // Per scored moment, one value per scored update: the image's PSNR against the truth's; the held
  // volume's relative irradiance RMSE against the converged one (pooled over the probes, and each
  // probe relative to its own energy, so dim ones count as much).
  std::vector<std::vector<double>> psnr, probeError, probeErrorEach;
};

// Pearson's correlation of a and b, each value raised to `power` first (1/3: of the cube roots,
// the scale the encoder's thresholds follow).
double pearson(const std::vector<float>& a, const std::vector<float>& b, double power);
// The mean of v[from, to) (0 for none).
double mean(const std::vector<double>& v, size_t from, size_t to);

// A phase's scored updates: its last ones, each image against a converged volume at that update's t.
struct Moment {
  const char* name;
  uint32_t frame;  // the phase's last update
  uint32_t first;  // its first scored update
};

// The oracle stream's input for one update: the new estimate for the probes it re-sends, what the
// decoder holds for the rest. It re-sends, largest error cut first, until the held volume's error
// is within `ratio` × the full stream's (both against the truth): in this update, the fewest probes
// any rule that sends estimates could re-send for that error.
void oracleSelect(const float* truth, const float* estimate, const uint8_t* active, const float* full,
                  const float* held, uint32_t count, float ratio, float exponent, std::vector<float>& out);

std::string ruleName(const BlendRule& b);

// What every phase shares: the scene at t = 0, its grid, the phases' updates, the scored moments
// and the scored views (as the raster renders them and as a server knows them).
class Setup {
 public:
  Setup(const AdaptiveBenchOptions& options, renderer::VulkanContext& context);

  scene::Scene sceneAt(float t) const { return session::loadSceneOrThrow(o.sceneSpec, t); }
  // The light's t during update `frame` (0-based).
  float tAt(uint32_t frame) const {
    if (frame < o.stillUpdates) return 0.0f;
    return o.lightStep * static_cast<float>(std::min(frame - o.stillUpdates + 1, o.movingUpdates));
  }
  // Every scored view of a volume (the scene camera alone for mono, as a viewer sees it).
  std::vector<renderer::Image> renderWith(renderer::RasterRenderer& raster, const ProbeVolume& v) const {
    raster.setProbes(v);
    if (viewSpec.kind == renderer::ViewSetSpec::Kind::Mono)
      return std::vector<renderer::Image>{raster.render(raster.viewProjection(camera), camera.position)};
    return raster.renderViews(views);
  }
  std::vector<renderer::Image> render(const ProbeVolume& v, float t) const {
    renderer::RasterRenderer raster(context, sceneAt(t), o.width, o.height, singleSampleRaster());
    return renderWith(raster, v);
  }
  // The mean squared error of a set of views' pixels together (after gamma, as PSNR takes it).
  double mseOf(const std::vector<renderer::Image>& images, const std::vector<renderer::Image>& truth) const {
    double mse = 0;
    for (size_t i = 0; i < images.size(); ++i)
      mse += imaging::compareImages(images[i].rgb, truth[i].rgb, static_cast<int>(o.width), static_cast<int>(o.height)).mse;
    return mse / static_cast<double>(images.size());
  }
  // One PSNR for a set of views: of their pixels together.
  double psnrOf(const std::vector<renderer::Image>& images, const std::vector<renderer::Image>& truth) const {
    const double mse = mseOf(images, truth);
    return mse > 0 ? 10.0 * std::log10(1.0 / mse) : HUGE_VAL;
  }

  const AdaptiveBenchOptions& o;
  renderer::VulkanContext& context;
  scene::Scene first;
  ProbeGrid grid;
  uint32_t count = 0;
  uint32_t frames = 0;  // still, moving, still again
  StreamLayout layout;
  std::vector<Moment> moments;  // where images are scored: the end of each phase
  renderer::CameraView camera;
  renderer::ViewSetSpec viewSpec;
  std::vector<renderer::ViewInfo> views;
  // The scored views as a server knows them (what a subscriber sends), for the view weights a
  // server works out itself (renderer/probe_interest.h): "surface" from the geometry the views show,
  // "lit" also from the light the volume holds. Without probe offsets: the scored renders here
  // draw every volume at the grid positions.
  std::vector<View> serverViews;
  glm::uvec2 sampleSize{0, 0};  // as the producer samples them
  renderer::SurfaceLighting firstLighting;
};

// The truth at every t a scored update has: the views of a converged float volume, and the volume.
class Truth {
 public:
  explicit Truth(const Setup& setup) : s_(setup) {}
  void converge(float t, bool withImage);
  const std::vector<float>& probes(float t) const { return probes_.at(t); }
  const std::vector<renderer::Image>& images(float t) const { return images_.at(t); }

 private:
  const Setup& s_;
  std::map<float, std::vector<renderer::Image>> images_;
  std::map<float, std::vector<float>> probes_;
};

// The noise-aware stream's view weights for AdaptiveBenchOptions::viewWeights = "footprint".
struct Footprint {
  std::vector<float> weights;  // per probe (empty: not measured)
  nlohmann::json match;        // how well the server's own estimates follow them
};

// Each probe's share of the scored views, measured on the converged volume at the start: the
// views' squared change (after gamma) when that probe alone is made 20 % brighter.
Footprint measureFootprint(const Setup& s, Truth& truth);

// The scored views' surfaces and the light on them, for the "surface" and "lit" view weights; the
// light follows the scene as it moves.
struct SeenSurfaces {
  std::vector<renderer::ViewSample> samples;  // empty: neither weight
  renderer::SurfaceLighting lighting;
  std::vector<glm::vec3> direct;  // sampleDirectLight, again when the lights move
  std::vector<float> litWeights;  // blended over the updates, as the producer does
};

// One rule with one seed through the three phases: what it measured.
struct RuleRun {
  BlendRule rule;
  uint32_t seed = 0;
  uint32_t activeProbes = 0;
  std::vector<double> changes;     // per update: the volume's relative irradiance change
  std::vector<uint32_t> restarts;  // per update: probes whose history was rejected
  std::vector<Stream> streams;     // each with its bytes, held changes and scores
};

// One rule with one seed through the three phases (adaptive_rules.cpp).
RuleRun runRule(const Setup& s, const Truth& truth, const std::vector<float>& footprint, uint32_t seed,
                const BlendRule& rule);

// The report (adaptive_report.cpp): the settings and the table's head; a rule's JSON (for the first
// seed also its table rows and its streams on the bytes chart); the bytes chart; the light jump;
// the headline; the ray budget against brute force; the adaptive rule over seeds.
void writeHeader(const Setup& s, const Footprint& footprint, AdaptiveBenchResult& r);
nlohmann::json reportRule(const Setup& s, const RuleRun& run, bool firstSeed, std::string& table,
                          std::vector<imaging::ChartSeries>& bytesSeries);
std::string bytesChart(const AdaptiveBenchOptions& o, const std::vector<imaging::ChartSeries>& bytesSeries);
void addJump(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, const std::vector<BlendRule>& rules,
             AdaptiveBenchResult& r);
void addSummary(nlohmann::json& j);
void addReconvergence(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r);
void addSeedSummary(const std::vector<nlohmann::json>& bySeed, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r);

}  // namespace probecast::bench::adaptive
