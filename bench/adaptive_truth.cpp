// bench adaptive: what every phase works with (the scene, its grid and the scored views; the
// converged volumes, cached by --truth-cache) and each probe's footprint in the views.
#include "adaptive_parts.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/probe_file.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"

namespace probecast::bench::adaptive {
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

}  // namespace

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

std::string ruleName(const BlendRule& b) {
  return b.rejectSigmas > 0 ? fmt::format("adaptive k={:g}", b.rejectSigmas) : fmt::format("w_min {:g}", b.wMin);
}

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

}  // namespace probecast::bench::adaptive
