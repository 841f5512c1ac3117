#include "adaptive_bench.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <filesystem>
#include <map>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/probe_file.h"
#include "probecast/codec/stream.h"
#include "probecast/imaging/image_metrics.h"
#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"
#include "harness.h"
#include "reconvergence.h"
#include "stability.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

// The converged volumes' recipe (the updater's settings below and its code): raise it when either
// changes what they converge to, so --truth-cache files of the old one are not read.
constexpr int kTruthVolumeVersion = 1;

// --truth-cache: a converged volume's file, named by everything it is made of.
std::string truthCachePath(const std::string& dir, const scene::Scene& scene, const std::array<uint32_t, 3>& dims,
                           const renderer::UpdaterOptions& ro, int updates) {
  const nlohmann::json key = {{"truth_version", kTruthVolumeVersion},
                              {"scene_hash", sceneContentHash(scene)},
                              {"grid", {dims[0], dims[1], dims[2]}},
                              {"spp", ro.samplesPerProbe},
                              {"updates", updates},
                              {"seed", ro.seed}};
  return dir + "/truth_" + referenceKeyStem(key) + ".pcpv";
}

// The cached volume when its file is there and sound (checksum, values, `count` probes); a file
// that is not is said so, and converged again by the caller.
bool readTruth(const std::string& path, uint32_t count, ProbeVolume& out,
               const std::function<void(const std::string&)>& progress) {
  if (!std::filesystem::exists(path)) return false;
  std::string why;
  if (readProbeFile(path, out, why) && out.probes.size() == static_cast<size_t>(count) * kProbeFloats) return true;
  sayProgress(progress, fmt::format("adaptive bench: {} unusable ({}); converging again", path, why.empty() ? "another grid" : why));
  return false;
}

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
double pearson(const std::vector<float>& a, const std::vector<float>& b, double power) {
  const size_t n = std::min(a.size(), b.size());
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < n; ++i) {
    const double x = std::pow(std::max<double>(a[i], 0.0), power), y = std::pow(std::max<double>(b[i], 0.0), power);
    sa += x, sb += y, saa += x * x, sbb += y * y, sab += x * y;
  }
  const double dn = static_cast<double>(n);
  const double cov = sab - sa * sb / dn, va = saa - sa * sa / dn, vb = sbb - sb * sb / dn;
  return va > 0 && vb > 0 ? cov / std::sqrt(va * vb) : 0.0;
}

double mean(const std::vector<double>& v, size_t from, size_t to) {
  if (to <= from) return 0.0;
  return std::accumulate(v.begin() + static_cast<long>(from), v.begin() + static_cast<long>(to), 0.0) /
         static_cast<double>(to - from);
}

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
                  const float* held, uint32_t count, float ratio, float exponent, std::vector<float>& out) {
  out.assign(held, held + static_cast<size_t>(count) * kProbeFloats);
  std::vector<std::pair<double, uint32_t>> cuts;
  double heldErr = 0, fullErr = 0;
  for (uint32_t p = 0; p < count; ++p) {
    if (!active[p]) continue;
    const size_t at = static_cast<size_t>(p) * kProbeFloats;
    double h = 0, n = 0, energy = 0, again = 0;
    irradianceErrorEnergy(held + at, truth + at, h, energy);
    irradianceErrorEnergy(full + at, truth + at, n, again);
    const double weight = energy > 0 ? std::pow(energy, -static_cast<double>(exponent)) : 0.0;
    h *= weight;
    n *= weight;
    heldErr += h;
    fullErr += n;
    if (h > n) cuts.push_back({h - n, p});
  }
  std::sort(cuts.begin(), cuts.end(), std::greater<>());
  const double target = static_cast<double>(ratio) * ratio * fullErr;
  for (const auto& [cut, p] : cuts) {
    if (heldErr <= target) break;
    std::copy(estimate + static_cast<size_t>(p) * kProbeFloats, estimate + static_cast<size_t>(p + 1) * kProbeFloats,
              out.begin() + static_cast<long>(p) * kProbeFloats);
    heldErr -= cut;
  }
}

}  // namespace

namespace {

// The ray budget's part of the bench: its JSON and table lines. The first seed's jump is kept in
// full; every seed's ratio is listed and the summary takes their median.
void addReconvergence(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r) {
  ReconvergenceOptions ro;
  ro.sceneSpec = o.sceneSpec;
  ro.dims = o.dims;
  ro.samplesPerProbe = o.samplesPerProbe;
  ro.raysPerUpdate = o.raysPerUpdate;
  ro.viewYfov = o.viewYfov;
  ro.rejectSigmas = o.rejectSigmas;
  ro.neighbourHistory = o.neighbourHistory;
  ro.changeHistory = o.changeHistory;
  ro.afterUpdates = o.reconvergenceUpdates;
  const auto updates = [&](int n) { return n < 0 ? "> " + std::to_string(ro.afterUpdates) : std::to_string(n); };
  const auto ratioText = [](const ReconvergenceResult& rc) {
    return rc.ratio >= 0 ? fmt::format("{:.3f}", rc.ratio)
                         : rc.ratioAtMost >= 0 ? fmt::format("< {:.3f}", rc.ratioAtMost) : std::string("n/a");
  };
  std::vector<double> ratios;  // a seed whose budget never got there counts as infinitely slow
  for (uint32_t k = 0; k < std::max(o.reconvergenceSeeds, 1u); ++k) {
    ro.seed = o.seed + k;
    if (o.progress) o.progress(fmt::format("adaptive bench: ray budget against brute force, seed {}", ro.seed));
    const ReconvergenceResult rc = measureReconvergence(context, ro);
    const double ratio = rc.ratio >= 0 ? rc.ratio : rc.ratioAtMost >= 0 ? rc.ratioAtMost : HUGE_VAL;
    ratios.push_back(ratio);
    r.json["reconvergence_seeds"].push_back({{"seed", ro.seed},
                                             {"adaptive_updates", rc.adaptiveUpdates},
                                             {"bruteforce_updates", rc.bruteForceUpdates},
                                             {"reconvergence_vs_bruteforce_at_most", std::isfinite(ratio) ? ratio : -1.0}});
    if (k == 0) {
      r.json["reconvergence"] = rc.json();
      r.json["rays_per_update"] = rc.raysPerUpdate;
      r.json["summary"]["rays_per_update"] = rc.raysPerUpdate;
      r.table += fmt::format(
          "ray budget, light jump t 0 -> 0.5 after {} still updates, {} rays per update, {} of {} probes in view:\n",
          ro.convergeUpdates, rc.raysPerUpdate, rc.inViewProbes, rc.activeProbes);
    }
    r.table += fmt::format(
        "  seed {}: in-view error back to {:.4f} (brute force before the jump) after {} updates with the budget, {} "
        "brute force: ratio {}\n",
        ro.seed, rc.threshold, updates(rc.adaptiveUpdates), updates(rc.bruteForceUpdates), ratioText(rc));
  }
  const double median = session::median(ratios);
  r.json["summary"]["reconvergence_vs_bruteforce"] = std::isfinite(median) ? median : -1.0;
  r.json["summary"]["reconvergence_vs_bruteforce_at_most"] = std::isfinite(median) ? median : -1.0;
  r.json["summary"]["reconvergence_seeds"] = ratios.size();
  r.table += std::isfinite(median) ? fmt::format("  median ratio over {} seeds: {:.3f}\n", ratios.size(), median)
                                   : fmt::format("  median ratio over {} seeds: n/a\n", ratios.size());
}

}  // namespace

// The noise-aware stream of the adaptive rule over seeds: each figure per seed, its mean, and the
// standard error of that mean (the spread between seeds is the bench's own noise).
void addSeedSummary(const std::vector<nlohmann::json>& bySeed, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r) {
  const auto noiseStream = [](const nlohmann::json& rule) -> const nlohmann::json& { return rule["streams"][2]; };
  const std::vector<std::pair<std::string, std::function<double(const nlohmann::json&)>>> figures = {
      {"first_still_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["first_still_bytes_per_probe_frame"].get<double>(); }},
      {"moving_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["moving_bytes_per_probe_frame"].get<double>(); }},
      {"static_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["static_bytes_per_probe_frame"].get<double>(); }},
      {"psnr_loss_db_still", [](const nlohmann::json& s) { return s["psnr_loss_db"]["still"].get<double>(); }},
      {"psnr_loss_db_moving", [](const nlohmann::json& s) { return s["psnr_loss_db"]["moving"].get<double>(); }},
      {"psnr_loss_db_still_again", [](const nlohmann::json& s) { return s["psnr_loss_db"]["still_again"].get<double>(); }},
      {"probe_error_rel_moving", [](const nlohmann::json& s) { return s["probe_error_rel"]["moving"].get<double>(); }},
      {"probe_error_rel_per_probe_moving",
       [](const nlohmann::json& s) { return s["probe_error_rel_per_probe"]["moving"].get<double>(); }}};
  nlohmann::json& out = r.json["stream_seeds"];
  out["seeds"] = nlohmann::json::array();
  for (const nlohmann::json& rule : bySeed) out["seeds"].push_back(rule["seed"]);
  out["rule"] = bySeed.front()["rule"];
  out["stream"] = noiseStream(bySeed.front())["stream"];
  for (const nlohmann::json& rule : bySeed)
    out["psnr_loss_db_per_update"].push_back(noiseStream(rule)["psnr_loss_db_per_update"]);
  r.table += fmt::format("noise-aware stream of the adaptive rule over seeds {}-{} (mean ± standard error):\n", o.seed,
                         o.seed + bySeed.size() - 1);
  for (const auto& [name, get] : figures) {
    std::vector<double> v;
    for (const nlohmann::json& rule : bySeed) v.push_back(get(noiseStream(rule)));
    const double m = mean(v, 0, v.size());
    double var = 0;
    for (double x : v) var += (x - m) * (x - m);
    const double se = std::sqrt(var / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
    out["figures"][name] = {{"per_seed", v}, {"mean", m}, {"standard_error", se}};
    r.table += fmt::format("  {:<36} {:>8.3f} ± {:.3f}  (", name, m, se);
    for (size_t i = 0; i < v.size(); ++i) r.table += fmt::format("{}{:.3f}", i ? " " : "", v[i]);
    r.table += ")\n";
  }
}

namespace {

std::string ruleName(const BlendRule& b) {
  return b.rejectSigmas > 0 ? fmt::format("adaptive k={:g}", b.rejectSigmas) : fmt::format("w_min {:g}", b.wMin);
}

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

Setup::Setup(const AdaptiveBenchOptions& options, renderer::VulkanContext& vulkan)
    : o(options), context(vulkan), first(sceneAt(0.0f)) {
  grid = renderer::sceneGrid(first, o.dims);
  count = grid.count();
  frames = 2 * o.stillUpdates + o.movingUpdates;
  layout = streamLayoutFor(grid, o.repr, 4);
  const auto phaseEnd = [&](const char* name, uint32_t last, uint32_t length) {
    return Moment{name, last, last + 1 - std::min(o.scoredUpdates, length)};
  };
  moments = {phaseEnd("still", o.stillUpdates - 1, o.stillUpdates),
             phaseEnd("moving", o.stillUpdates + o.movingUpdates - 1, o.movingUpdates),
             phaseEnd("still_again", frames - 1, o.stillUpdates)};
  camera = renderer::CameraView::fromScene(first);
  std::string viewError;
  if (!renderer::parseViewSet(o.scoredViews, viewSpec, viewError))
    throw std::invalid_argument("bench adaptive: scored views: " + viewError);
  renderer::ViewSetOptions viewOptions;
  viewOptions.aspect = static_cast<float>(o.width) / static_cast<float>(o.height);
  views = renderer::makeViewSet(camera, viewSpec, viewOptions);
  std::vector<renderer::ViewInfo> scored = views;
  if (viewSpec.kind == renderer::ViewSetSpec::Kind::Mono) {
    const renderer::RasterRenderer raster(context, first, o.width, o.height, singleSampleRaster());
    scored.assign(1, renderer::ViewInfo{});
    scored[0].viewProj = raster.viewProjection(camera);
    scored[0].eye = camera.position;
  }
  serverViews = session::priorityViews(scored);
  sampleSize = renderer::footprintSampleSize(serverViews.size());
  firstLighting = renderer::surfaceLighting(first, scene::AreaLightOptions{});
}

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

void Truth::converge(float t, bool withImage) {
  const AdaptiveBenchOptions& o = s_.o;
  if (probes_.count(t) && (!withImage || images_.count(t))) return;
  const scene::Scene sceneNow = s_.sceneAt(t);
  renderer::UpdaterOptions ro;
  ro.samplesPerProbe = 512;
  ro.rejectSigmas = 0.0f;
  ro.seed = 4242;
  ro.surfaceProbesOnly = false;  // every probe: the streams are scored on the probes they hold
  constexpr int kUpdates = 16;
  const std::string path = o.truthCache.empty() ? std::string() : truthCachePath(o.truthCache, sceneNow, o.dims, ro, kUpdates);
  ProbeVolume stored;
  if (!path.empty() && readTruth(path, s_.count, stored, o.progress)) {
    if (withImage) images_.emplace(t, s_.render(stored, t));
    probes_.emplace(t, std::move(stored.probes));
    return;
  }
  sayProgress(o.progress, fmt::format("adaptive bench: converged volume at t = {:g}", t));
  renderer::ProbeUpdater u(s_.context, sceneNow, s_.grid, ro);
  for (int k = 0; k < kUpdates; ++k) u.update();
  if (!path.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.truthCache, ec);
    if (ec) throw std::runtime_error("--truth-cache " + o.truthCache + ": " + ec.message());
    std::vector<uint8_t> bytes;
    serializeProbeVolume(u.volume(), bytes);
    writeFileAtomically(path, std::string(bytes.begin(), bytes.end()));
  }
  if (withImage) images_.emplace(t, s_.render(u.volume(), t));
  probes_.emplace(t, u.volume().probes);
}

// The noise-aware stream's view weights for AdaptiveBenchOptions::viewWeights = "footprint".
struct Footprint {
  std::vector<float> weights;  // per probe (empty: not measured)
  nlohmann::json match;        // how well the server's own estimates follow them
};

// Each probe's share of the scored views, measured on the converged volume at the start: the
// views' squared change (after gamma) when that probe alone is made 20 % brighter.
Footprint measureFootprint(const Setup& s, Truth& truth) {
  truth.converge(s.tAt(0), false);
  sayProgress(s.o.progress, "adaptive bench: each probe's footprint in the scored views");
  const scene::Scene sceneNow = s.sceneAt(s.tAt(0));
  const std::vector<float>& converged = truth.probes(s.tAt(0));
  renderer::RasterRenderer raster(s.context, sceneNow, s.o.width, s.o.height, singleSampleRaster());
  ProbeVolume v = makeProbeVolume(s.grid);
  v.probes = converged;
  const std::vector<renderer::Image> base = s.renderWith(raster, v);
  Footprint fp;
  fp.weights.assign(s.count, 0.0f);
  for (uint32_t p = 0; p < s.count; ++p) {
    float* c = v.probes.data() + static_cast<size_t>(p) * kProbeFloats;
    if (std::all_of(c, c + kProbeFloats, [](float x) { return x == 0.0f; })) continue;  // inactive or black
    for (int i = 0; i < kProbeFloats; ++i) c[i] *= 1.2f;
    fp.weights[p] = static_cast<float>(s.mseOf(s.renderWith(raster, v), base));  // weights count relative to each other
    for (int i = 0; i < kProbeFloats; ++i) c[i] = converged[static_cast<size_t>(p) * kProbeFloats + i];
  }
  // How well the server's own estimates follow the measured weights (on the same converged volume).
  std::vector<uint8_t> lit(s.count, 0);
  for (uint32_t p = 0; p < s.count; ++p) {
    const float* c = v.probes.data() + static_cast<size_t>(p) * kProbeFloats;
    lit[p] = std::any_of(c, c + kProbeFloats, [](float x) { return x != 0.0f; });
  }
  const std::vector<renderer::ViewSample> seen =
      renderer::sampleViewSurfaces(sceneNow, s.grid, lit, {}, s.serverViews, s.sampleSize.x, s.sampleSize.y);
  const std::pair<const char*, std::vector<float>> estimates[] = {
      {"surface", renderer::probeViewFootprints(seen, s.count)},
      {"lit", renderer::probeViewSensitivity(seen, renderer::sampleDirectLight(sceneNow, seen, s.firstLighting),
                                             s.firstLighting, v.probes, s.count)}};
  for (const auto& [name, w] : estimates)
    fp.match[name] = {{"pearson", pearson(w, fp.weights, 1.0)}, {"pearson_cube_roots", pearson(w, fp.weights, 1.0 / 3.0)}};
  return fp;
}

// The bench's settings in the JSON, and the table's head.
void writeHeader(const Setup& s, const Footprint& footprint, AdaptiveBenchResult& r) {
  const AdaptiveBenchOptions& o = s.o;
  nlohmann::json& j = r.json;
  j["command"] = o.command;
  j["codec_format_version"] = kFormatVersion;  // the stream bytes below are of this format
  j["device"] = s.context.deviceName();
  j["scene"] = s.first.name;
  j["grid"] = {o.dims[0], o.dims[1], o.dims[2]};
  j["samples_per_probe"] = o.samplesPerProbe;
  j["seed"] = o.seed;
  j["phases"] = {{"still", o.stillUpdates}, {"moving", o.movingUpdates}, {"still_again", o.stillUpdates},
                 {"light_step_t", o.lightStep}};
  j["representation"] = representationName(o.repr);
  j["surface_probes_only"] = o.surfaceProbesOnly;
  j["view_weights"] = o.viewWeights;
  if (!footprint.weights.empty())  // of the grid
    j["probes_that_change_no_pixel"] = std::count(footprint.weights.begin(), footprint.weights.end(), 0.0f);
  if (!footprint.match.is_null()) j["view_weight_estimates_vs_footprint"] = footprint.match;
  j["deadzone"] = o.deadzone;
  j["noise_scale"] = o.noiseScale;
  j["confirmations"] = o.confirmations;
  j["refinement_interval"] = o.refinementInterval;
  j["change_history"] = o.changeHistory;
  j["scored_views"] = o.scoredViews;
  j["metric"] = "flicker: median relative irradiance change per update over the last half of a still phase; PSNR of "
                "the raster view against the one from a converged float volume (plain gamma 2.2); probe error: relative "
                "irradiance RMSE of the held volume against that converged volume (probe_error_rel: pooled over the "
                "probes, so bright ones dominate; probe_error_rel_per_probe: each probe relative to its own energy, "
                "RMS over the probes)";
  r.table = fmt::format("adaptive bench: {} {}x{}x{} probes, {} spp, {}, dead-zone {}, on {}\n", s.first.name, o.dims[0],
                        o.dims[1], o.dims[2], o.samplesPerProbe, representationName(o.repr), o.deadzone,
                        s.context.deviceName());
  r.table += fmt::format("images: {} view{} ({}) at the last {} updates of each phase\n", s.views.size(),
                         s.views.size() == 1 ? "" : "s", o.scoredViews, o.scoredUpdates);
  r.table += fmt::format("{:<14} {:<7} {:>9} {:>9} {:>9} {:>9} {:>11} {:>11}\n", "rule", "stream", "still B",
                         "moving B", "again B", "flicker", "held flick", "PSNR loss");
}

// The streams one rule's volumes go through: every quantised change, the dead-zone, the
// noise-aware stream, and the oracles.
std::vector<Stream> makeStreams(const Setup& s, const std::vector<float>& footprint) {
  const AdaptiveBenchOptions& o = s.o;
  std::vector<Stream> streams(3);
  streams[0].name = "full";  // every quantised change
  streams[1].name = "deadzone";
  streams[1].options.deadzone = o.deadzone;
  streams[2].name = "noise";
  streams[2].options.deadzone = o.deadzone;
  streams[2].options.noiseScale = o.noiseScale;
  streams[2].options.confirmations = o.confirmations;
  streams[2].options.refinementInterval = o.refinementInterval;
  streams[2].withNoise = true;
  streams[2].viewWeights = footprint;
  for (float exponent : o.oracleExponents)
    for (float ratio : o.oracleErrorRatios) {
      Stream& st = streams.emplace_back();
      st.name = fmt::format("oracle {:g}/{:g}", ratio, exponent);
      st.oracleRatio = ratio;
      st.oracleExponent = exponent;
      st.options.deadzone = o.deadzone;
    }
  return streams;
}

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

// Every stream takes the update's volume (the oracles what they choose of it) and writes its frame.
void encodeUpdate(const Setup& s, const Truth& truth, uint32_t f, const ProbeVolume& v, std::vector<Stream>& streams) {
  std::vector<float> oracleInput;
  std::vector<uint8_t> frame;
  for (Stream& st : streams) {
    const float* input = v.probes.data();
    if (st.oracleRatio > 0.0f) {
      // What knows the truth: re-send the fewest probes (largest error cut first) that bring the
      // held volume's error to the stream's ratio × the full stream's; the rest input what is held.
      oracleSelect(truth.probes(s.tAt(f)).data(), v.probes.data(), v.active.data(), streams[0].encoder->reconstruction(),
                   st.encoder->reconstruction(), s.count, st.oracleRatio, st.oracleExponent, oracleInput);
      input = oracleInput.data();
    }
    const uint32_t changed = st.encoder->update(input, v.active.data(), st.withNoise ? v.noise.data() : nullptr,
                                                st.withNoise ? v.stillUpdates.data() : nullptr);
    st.encoder->writeChangedFrame(frame);
    // Frame 0 is the keyframe; a frame that changes no brick is never sent.
    st.bytesPerProbe.push_back(f == 0 || changed == 0 ? 0.0 : static_cast<double>(frame.size()) / s.count);
    ProbeVolume held;
    st.encoder->copyVolume(s.grid.bounds, held);
    st.heldChanges.push_back(st.held.empty() ? 0.0
                                             : irradianceRmseRel(held.probes.data(), st.held.data(), held.active.data(),
                                                                 s.count));
    st.held = std::move(held.probes);
  }
}

// At a scored update: what each stream holds against the truth, as probes and as images.
void scoreUpdate(const Setup& s, const Truth& truth, uint32_t f, std::vector<Stream>& streams) {
  for (size_t m = 0; m < s.moments.size(); ++m) {
    if (f < s.moments[m].first || f > s.moments[m].frame) continue;
    const std::vector<float>& converged = truth.probes(s.tAt(f));
    for (Stream& st : streams) {
      ProbeVolume held;
      st.encoder->copyVolume(s.grid.bounds, held);
      st.probeError[m].push_back(irradianceRmseRel(held.probes.data(), converged.data(), held.active.data(), s.count));
      st.probeErrorEach[m].push_back(
          irradianceRmseRelPerProbe(held.probes.data(), converged.data(), held.active.data(), s.count));
      st.psnr[m].push_back(s.psnrOf(s.render(held, s.tAt(f)), truth.images(s.tAt(f))));
    }
  }
}

renderer::UpdaterOptions updaterOptions(const AdaptiveBenchOptions& o, uint32_t seed, const BlendRule& rule) {
  renderer::UpdaterOptions uo;
  uo.samplesPerProbe = o.samplesPerProbe;
  uo.seed = seed;
  uo.minBlendWeight = rule.wMin;
  uo.rejectSigmas = rule.rejectSigmas;
  uo.neighbourHistory = rule.rejectSigmas > 0 ? o.neighbourHistory : 0.0f;
  uo.changeHistory = rule.rejectSigmas > 0 ? o.changeHistory : 0.0f;
  uo.surfaceProbesOnly = o.surfaceProbesOnly;
  return uo;
}

RuleRun runRule(const Setup& s, const Truth& truth, const std::vector<float>& footprint, uint32_t seed,
                const BlendRule& rule) {
  const AdaptiveBenchOptions& o = s.o;
  renderer::ProbeUpdater u(s.context, s.first, s.grid, updaterOptions(o, seed, rule));
  RuleRun run{rule, seed, s.count - u.classifyStats().inactive, {}, {}, makeStreams(s, footprint)};
  std::vector<Stream>& streams = run.streams;
  SeenSurfaces seen;
  seen.lighting = s.firstLighting;
  if (o.viewWeights == "surface" || o.viewWeights == "lit") {
    seen.samples = renderer::sampleViewSurfaces(s.first, s.grid, u.volume().active, {}, s.serverViews, s.sampleSize.x,
                                                s.sampleSize.y);
    if (o.viewWeights == "surface") streams[2].viewWeights = renderer::probeViewFootprints(seen.samples, s.count);
  }
  if (!seen.samples.empty()) seen.direct = renderer::sampleDirectLight(s.first, seen.samples, seen.lighting);
  for (Stream& st : streams) {
    st.encoder = std::make_unique<StreamEncoder>(s.layout, st.options);
    // The views' own weights: a probe's active flag in this updater may differ from the truth's.
    if (!st.viewWeights.empty() && !st.encoder->setViewWeights(st.viewWeights))
      throw std::runtime_error("bench adaptive: no probe shows in the scored views");
    st.psnr.assign(s.moments.size(), {});
    st.probeError = st.probeErrorEach = st.psnr;
  }
  std::vector<float> previous;
  for (uint32_t f = 0; f < s.frames; ++f) {
    if (f >= o.stillUpdates && f < o.stillUpdates + o.movingUpdates) {
      const scene::Scene now = s.sceneAt(s.tAt(f));
      u.setScene(now);
      if (!seen.samples.empty() && now.lights != seen.lighting.lights) {
        seen.lighting.lights = now.lights;
        seen.direct = renderer::sampleDirectLight(now, seen.samples, seen.lighting);
      }
    }
    run.restarts.push_back(u.update().restartedProbes);
    const ProbeVolume& v = u.volume();
    if (o.viewWeights == "lit") {
      renderer::blendViewWeights(seen.litWeights, renderer::probeViewSensitivity(seen.samples, seen.direct,
                                                                                 seen.lighting, v.probes, s.count));
      if (!streams[2].encoder->setViewWeights(seen.litWeights))
        streams[2].encoder->setViewWeights({});  // nothing the views show is lit yet: as the hub does
    }
    run.changes.push_back(previous.empty() ? 0.0
                                           : irradianceRmseRel(v.probes.data(), previous.data(), v.active.data(), s.count));
    previous = v.probes;
    encodeUpdate(s, truth, f, v, streams);
    scoreUpdate(s, truth, f, streams);
  }
  return run;
}

// A stream's figures: bytes per phase, the flicker of what it holds, and per scored moment its
// PSNR, probe error and PSNR loss against the full stream.
nlohmann::json streamJson(const Setup& s, const RuleRun& run, const Stream& st) {
  const AdaptiveBenchOptions& o = s.o;
  const size_t a = o.stillUpdates, b = o.stillUpdates + o.movingUpdates;
  nlohmann::json sj = {{"stream", st.name},
                       {"static_bytes_per_probe_frame", mean(st.bytesPerProbe, s.frames - o.stillUpdates / 2, s.frames)},
                       {"first_still_bytes_per_probe_frame", mean(st.bytesPerProbe, a / 2, a)},
                       {"moving_bytes_per_probe_frame", mean(st.bytesPerProbe, a, b)},
                       {"bytes_per_probe_frame", st.bytesPerProbe}};
  // Flicker of what a subscriber holds, over the last half of the second still phase: the
  // median as for the volume, and the mean, which counts the updates that change nothing.
  const std::vector<double> heldTail(st.heldChanges.end() - o.stillUpdates / 2, st.heldChanges.end());
  sj["held_flicker_rel_median"] = session::median(heldTail);
  sj["held_flicker_rel_mean"] = mean(heldTail, 0, heldTail.size());
  double worstLoss = 0;
  for (size_t m = 0; m < s.moments.size(); ++m) {
    // The loss is paired update by update against the stream that sends every change (same
    // noise in the volume, same truth), then averaged; its standard error says what it resolves.
    const std::vector<double>& mine = st.psnr[m];
    std::vector<double> loss(mine.size());
    for (size_t i = 0; i < mine.size(); ++i) loss[i] = run.streams[0].psnr[m][i] - mine[i];
    const double meanLoss = mean(loss, 0, loss.size());
    double var = 0;
    for (double x : loss) var += (x - meanLoss) * (x - meanLoss);
    const double se = loss.size() > 1 ? std::sqrt(var / static_cast<double>(loss.size() - 1) / static_cast<double>(loss.size())) : 0.0;
    const char* moment = s.moments[m].name;
    sj["psnr_db"][moment] = mean(mine, 0, mine.size());
    sj["probe_error_rel"][moment] = mean(st.probeError[m], 0, st.probeError[m].size());
    sj["probe_error_rel_per_probe"][moment] = mean(st.probeErrorEach[m], 0, st.probeErrorEach[m].size());
    sj["psnr_loss_db"][moment] = meanLoss;
    sj["psnr_loss_standard_error_db"][moment] = se;
    sj["psnr_loss_db_per_update"][moment] = loss;
    worstLoss = std::max(worstLoss, meanLoss);
  }
  sj["worst_psnr_loss_db"] = worstLoss;
  return sj;
}

// A rule's JSON; for the first seed also its table rows and its streams on the bytes chart (fixed
// rules as streamed today, the adaptive rule both ways).
nlohmann::json reportRule(const Setup& s, const RuleRun& run, bool firstSeed, std::string& table,
                          std::vector<imaging::ChartSeries>& bytesSeries) {
  const AdaptiveBenchOptions& o = s.o;
  nlohmann::json ruleJson = {{"rule", ruleName(run.rule)}, {"w_min", run.rule.wMin}, {"reject_sigmas", run.rule.rejectSigmas}};
  const auto flickerOver = [&](uint32_t end) {
    const std::vector<double> tail(run.changes.begin() + (end - o.stillUpdates / 2), run.changes.begin() + end);
    return session::median(tail);
  };
  ruleJson["flicker_rel"] = flickerOver(s.frames);
  ruleJson["restarted_probes_per_update"] = run.restarts;
  ruleJson["flicker_rel_first_still"] = flickerOver(o.stillUpdates);
  for (const Stream& st : run.streams) {
    const nlohmann::json sj = streamJson(s, run, st);
    ruleJson["streams"].push_back(sj);
    if (!firstSeed) continue;
    const size_t a = o.stillUpdates;
    table += fmt::format("{:<14} {:<7} {:>9.3f} {:>9.3f} {:>9.3f} {:>8.2f}% {:>10.2f}% {:>8.3f} dB\n", ruleName(run.rule),
                         st.name, mean(st.bytesPerProbe, a / 2, a), sj["moving_bytes_per_probe_frame"].get<double>(),
                         sj["static_bytes_per_probe_frame"].get<double>(), 100 * ruleJson["flicker_rel"].get<double>(),
                         100 * sj["held_flicker_rel_mean"].get<double>(), sj["worst_psnr_loss_db"].get<double>());
    if (st.name == "full") continue;
    const bool adaptiveNoise = run.rule.rejectSigmas > 0 && st.withNoise;
    if (!adaptiveNoise && st.withNoise) continue;
    imaging::ChartSeries series{ruleName(run.rule) + ", " + st.name + " stream", {}, true};
    for (uint32_t f = 1; f < s.frames; ++f) series.points.push_back({static_cast<double>(f), st.bytesPerProbe[f], ""});
    bytesSeries.push_back(std::move(series));
  }
  ruleJson["seed"] = run.seed;
  return ruleJson;
}

std::string bytesChart(const AdaptiveBenchOptions& o, const std::vector<imaging::ChartSeries>& bytesSeries) {
  imaging::ChartSpec spec;
  spec.title = fmt::format("Wire bytes per probe per frame: light still, moving (updates {}-{}), still", o.stillUpdates,
                           o.stillUpdates + o.movingUpdates);
  spec.xLabel = "update";
  spec.yLabel = "bytes per probe per frame";
  spec.footnote = o.command;
  return imaging::renderSvgChart(spec, bytesSeries);
}

// Every rule after a light jump on builtin:cornell 4³: the JSON, table lines and the error chart.
void addJump(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, const std::vector<BlendRule>& rules,
             AdaptiveBenchResult& r) {
  sayProgress(o.progress, "adaptive bench: light jump");
  const std::vector<FlickerLag> jump = measureFlickerLag(context, rules, o.samplesPerProbe, o.jumpUpdates);
  const auto updates = [&](int n) { return n < 0 ? "> " + std::to_string(o.jumpUpdates) : std::to_string(n); };
  const auto errorSeries = [](const std::string& name, const std::vector<double>& error) {
    imaging::ChartSeries series{name, {}, true};
    for (size_t k = 0; k < error.size(); ++k) series.points.push_back({static_cast<double>(k + 1), error[k], ""});
    return series;
  };
  std::vector<imaging::ChartSeries> jumpSeries;
  r.table += "light jump (builtin:cornell 4x4x4, t 0 -> 0.5):\n";
  for (size_t i = 0; i < jump.size(); ++i) {
    const FlickerLag& f = jump[i];
    r.json["jump"].push_back({{"rule", ruleName(rules[i])},
                              {"flicker_rel", f.flickerRel},
                              {"error_before_jump", f.errorBeforeJump},
                              {"error_after_jump", f.errorAfterJump},
                              {"fresh_error", f.freshError},
                              {"follow_updates", f.updatesToFollow},
                              {"reconvergence_updates", f.updatesToRecover}});
    r.table += fmt::format("  {:<14} follows in {} updates, back to the pre-jump error in {} (flicker {:.2f}%)\n",
                           ruleName(rules[i]), updates(f.updatesToFollow), updates(f.updatesToRecover), 100 * f.flickerRel);
    jumpSeries.push_back(errorSeries(ruleName(rules[i]), f.errorAfterJump));
  }
  jumpSeries.push_back(errorSeries("fresh start on the new lighting", jump.back().freshError));
  imaging::ChartSpec spec;
  spec.title = "Irradiance error after the light jumps (builtin:cornell, 4x4x4)";
  spec.xLabel = "updates after the jump";
  spec.yLabel = "relative irradiance RMSE against the converged new lighting";
  spec.logY = true;
  spec.footnote = o.command;
  r.svgJump = imaging::renderSvgChart(spec, jumpSeries);
}

// The headline: the adaptive rule with the noise-aware stream.
void addSummary(nlohmann::json& j) {
  const nlohmann::json& adaptive = j["rules"].back();
  const nlohmann::json& noise = adaptive["streams"][2];
  j["summary"] = {{"static_bytes_per_probe_frame", noise["static_bytes_per_probe_frame"]},
                  {"moving_bytes_per_probe_frame", noise["moving_bytes_per_probe_frame"]},
                  {"flicker_rel", adaptive["flicker_rel"]},
                  {"follow_updates", j["jump"].back()["follow_updates"]},
                  {"reconvergence_updates", j["jump"].back()["reconvergence_updates"]},
                  {"worst_psnr_loss_db", noise["worst_psnr_loss_db"]}};
}

// The fixed rules, then the adaptive one; the adaptive rule again with each further seed (its
// figures per seed; the tables and charts are the first seed's).
std::vector<std::pair<uint32_t, BlendRule>> ruleRuns(const AdaptiveBenchOptions& o, const std::vector<BlendRule>& rules) {
  std::vector<std::pair<uint32_t, BlendRule>> runs;  // (seed, rule)
  for (uint32_t extra = 0; extra < std::max(o.streamSeeds, 1u); ++extra)
    for (const BlendRule& rule : rules)
      if (extra == 0 || rule.rejectSigmas > 0) runs.push_back({o.seed + extra, rule});
  return runs;
}

}  // namespace

AdaptiveBenchResult runAdaptiveBench(const AdaptiveBenchOptions& o) {
  renderer::VulkanContext context(o.context);
  AdaptiveBenchResult r;
  if (o.reconvergenceOnly) {
    r.json["command"] = o.command;
    r.json["device"] = context.deviceName();
    r.json["samples_per_probe"] = o.samplesPerProbe;
    r.json["seed"] = o.seed;
    addReconvergence(context, o, r);
    return r;
  }
  const Setup s(o, context);
  // Converged float volumes where images are scored: the end of each phase.
  Truth truth(s);
  for (const Moment& m : s.moments)
    for (uint32_t f = m.first; f <= m.frame; ++f) truth.converge(s.tAt(f), true);
  const Footprint footprint = o.viewWeights == "footprint" ? measureFootprint(s, truth) : Footprint{};
  // The oracle stream needs the truth at every update.
  if (!o.oracleErrorRatios.empty())
    for (uint32_t f = 0; f < s.frames; ++f) truth.converge(s.tAt(f), false);
  writeHeader(s, footprint, r);

  std::vector<BlendRule> rules;
  for (float w : o.fixedWMins) rules.push_back({w, 0.0f});
  rules.push_back({0.0f, o.rejectSigmas});
  std::vector<imaging::ChartSeries> bytesSeries;
  std::vector<nlohmann::json> adaptiveBySeed;
  for (const auto& [seed, rule] : ruleRuns(o, rules)) {
    const bool firstSeed = seed == o.seed;
    sayProgress(o.progress,
                fmt::format("adaptive bench: {}{}", ruleName(rule), firstSeed ? "" : fmt::format(", seed {}", seed)));
    const RuleRun run = runRule(s, truth, footprint.weights, seed, rule);
    if (!r.json.contains("active_probes")) r.json["active_probes"] = run.activeProbes;  // the same for every rule
    nlohmann::json ruleJson = reportRule(s, run, firstSeed, r.table, bytesSeries);
    if (rule.rejectSigmas > 0) adaptiveBySeed.push_back(ruleJson);
    if (firstSeed) r.json["rules"].push_back(std::move(ruleJson));
  }
  if (std::max(o.streamSeeds, 1u) > 1) addSeedSummary(adaptiveBySeed, o, r);
  r.svgBytes = bytesChart(o, bytesSeries);
  addJump(context, o, rules, r);
  addSummary(r.json);
  addReconvergence(context, o, r);
  return r;
}

}  // namespace probecast::bench
