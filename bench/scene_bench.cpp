#include "scene_bench.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "harness.h"
#include "probecast/codec/record.h"
#include "probecast/imaging/image_io.h"
#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"

namespace probecast::bench {
namespace {

using Clock = std::chrono::steady_clock;

// PSNR as JSON: identical images give +inf, which JSON cannot hold.
nlohmann::json dbJson(double db) { return std::isfinite(db) ? nlohmann::json(db) : nlohmann::json(nullptr); }

// The most reference samples (pixels × views × spp) one run may ask for: ~10^11, days on lavapipe
// and minutes on a fast GPU; past it the request is surely a typo.
constexpr double kMaxReferenceSamples = 1e11;

void writePng(const std::string& path, const renderer::Image& image, float exposure) {
  std::string error;
  if (!imaging::writePngPreview(path, image.rgb, static_cast<int>(image.width), static_cast<int>(image.height), exposure,
                                error))
    throw std::runtime_error(error);
}

struct ReprRun {
  std::string name;
  bool viaCodec = false;
  Representation repr = Representation::L2;
};

// One representation's render of the view set: against the reference and the float render.
struct ReprResult {
  ReprRun run;
  double codecMs = 0;     // decode and upload
  double msPerView = 0;   // raster, median over the repeats
  std::vector<Comparison> perView;
  double psnr = 0, ssim = 0, psnrFloat = 0, ssimFloat = 0;  // means over the views
};

// What the bench measures: filled by the phases below, written by the report functions.
struct SceneMetrics {
  std::vector<Reference> refs;   // per view
  double floorMean = 0, accuracyMean = 0;
  std::vector<double> updateMs;  // per probe update
  double updateMedian = 0;
  std::vector<ReprResult> reprs;
};

// The scene and its views, as every phase sees them.
struct SceneSetup {
  const SceneBenchOptions& o;
  renderer::VulkanContext& context;
  std::vector<renderer::ViewInfo> views;
};

// References first: they are the slow part, and a cache hit makes re-runs cheap.
std::vector<Reference> sceneReferences(const SceneSetup& s, ReferenceCache& cache) {
  const SceneBenchOptions& o = s.o;
  std::vector<Reference> refs;
  for (size_t v = 0; v < s.views.size(); ++v) {
    ReferenceRequest request = referenceRequest(s.views[v].camera, o.width, o.height, o.referenceSpp,
                                                o.updater.environment, o.t);
    request.options.maxBounces = o.referenceBounces;
    request.options.seed = o.referenceSeed;
    sayProgress(o.progress, fmt::format("scene bench: reference for view {}/{}", v + 1, s.views.size()));
    refs.push_back(cache.get(o.scene, request));
  }
  return refs;
}

// The probe updates, each timed; returns the volume they make.
ProbeVolume updateProbes(const SceneSetup& s, SceneMetrics& metrics) {
  const SceneBenchOptions& o = s.o;
  renderer::ProbeUpdater updater(s.context, o.scene, o.grid, o.updater);
  for (uint32_t u = 0; u < o.updates; ++u) {
    const auto t0 = Clock::now();
    updater.update();
    metrics.updateMs.push_back(millisecondsSince(t0));
    sayProgress(o.progress,
                fmt::format("scene bench: probe update {}/{} ({:.0f} ms)", u + 1, o.updates, metrics.updateMs.back()));
  }
  metrics.updateMedian = session::medianMidpoint(metrics.updateMs);
  return updater.volume();
}

// A representation's views as PNGs, and their luminance difference after gamma against the
// reference, 0.1 shown as full red.
void writeReprImages(const SceneBenchOptions& o, const std::string& name, const std::vector<renderer::Image>& images,
                     const std::vector<Reference>& refs) {
  for (size_t v = 0; v < images.size(); ++v) {
    writePng(fmt::format("{}/{}_v{:02}.png", o.imagesDir, name, v), images[v], o.exposure);
    std::string diffError;
    if (!imaging::writeDifferencePng(fmt::format("{}/{}_v{:02}_difference.png", o.imagesDir, name, v), images[v].rgb,
                                     refs[v].mean.rgb, static_cast<int>(o.width), static_cast<int>(o.height), 0.1,
                                     diffError))
      throw std::runtime_error(diffError);
  }
}

// One representation through the raster: decode and upload, timed renders, every view compared.
// The float run (first) leaves its images in `floatImages` for the codec runs after it.
ReprResult measureRepresentation(const SceneSetup& s, renderer::RasterRenderer& raster, const ProbeVolume& volume,
                                 const ReprRun& run, const std::vector<Reference>& refs,
                                 std::vector<renderer::Image>& floatImages) {
  const SceneBenchOptions& o = s.o;
  ReprResult r;
  r.run = run;
  const auto c0 = Clock::now();
  raster.setProbes(run.viaCodec ? decodeAs(volume, run.repr, /*zh3PerPixel=*/true) : volume);
  r.codecMs = millisecondsSince(c0);
  std::vector<renderer::Image> images = raster.renderViews(s.views);  // warm-up (and shadow maps)
  std::vector<double> ms;
  for (uint32_t k = 0; k < o.repeats; ++k) {
    images = raster.renderViews(s.views);
    ms.push_back(raster.timings().viewsMs / static_cast<double>(s.views.size()));
  }
  if (!run.viaCodec) floatImages = images;
  r.msPerView = session::medianMidpoint(ms);
  const double n = static_cast<double>(s.views.size());
  for (size_t v = 0; v < s.views.size(); ++v) {
    const Comparison c = compareView(images[v], refs[v], floatImages[v], fmt::format("{} view {}", run.name, v));
    r.psnr += c.vsReference.psnrDb / n;
    r.ssim += c.vsReference.ssim / n;
    r.psnrFloat += c.vsFloat.psnrDb / n;
    r.ssimFloat += c.vsFloat.ssim / n;
    r.perView.push_back(c);
  }
  if (!o.imagesDir.empty()) writeReprImages(o, run.name, images, refs);
  return r;
}

nlohmann::json sceneJson(const SceneSetup& s, const std::string& cacheDir, const SceneMetrics& m) {
  const SceneBenchOptions& o = s.o;
  nlohmann::json json;
  json["command"] = o.command;
  json["scene"] = o.scene.name;
  json["device"] = s.context.deviceName();
  json["size"] = {o.width, o.height};
  json["supersample"] = o.raster.samplesPerSide;  // raster ms per view are for the supersampled size
  json["msaa_samples"] = o.raster.msaaSamples;
  json["texture_anisotropy"] = o.raster.anisotropy;
  json["views"] = o.views;
  json["view_count"] = s.views.size();
  json["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  json["bounds"] = {o.grid.bounds.min[0], o.grid.bounds.min[1], o.grid.bounds.min[2],
                    o.grid.bounds.max[0], o.grid.bounds.max[1], o.grid.bounds.max[2]};
  json["samples_per_probe"] = o.updater.samplesPerProbe;
  json["probe_updates"] = o.updates;
  json["update_ms_all"] = m.updateMs;
  json["environment"] = o.updater.environment ? o.updater.environment->name : "none";
  json["visibility"] = o.raster.visibility;
  json["area_lights"] = o.raster.areaLights.enabled;
  json["reference_cache"] = cacheDir;
  json["metric"] =
      "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2, per view, then the mean over views; the reference is "
      "the mean of two half-references of different seeds; noise floor = PSNR(half A, half B); the reference's own "
      "accuracy ~ floor + 6.02 dB";
  json["references"] = nlohmann::json::array();
  for (size_t v = 0; v < m.refs.size(); ++v)
    json["references"].push_back({{"view", v},
                                  {"key", m.refs[v].key},
                                  {"spp", o.referenceSpp},
                                  {"from_cache", m.refs[v].fromCache},
                                  {"seconds", m.refs[v].seconds},
                                  {"floor_psnr_db", dbJson(m.refs[v].floor.psnrDb)},
                                  {"floor_ssim", m.refs[v].floor.ssim},
                                  {"reference_psnr_db_estimate", dbJson(m.refs[v].accuracyDb)}});
  for (const ReprResult& r : m.reprs) {
    nlohmann::json perView = nlohmann::json::array();
    for (size_t v = 0; v < r.perView.size(); ++v)
      perView.push_back({{"view", v},
                         {"column", s.views[v].column},
                         {"row", s.views[v].row},
                         {"psnr_db", dbJson(r.perView[v].vsReference.psnrDb)},
                         {"ssim", r.perView[v].vsReference.ssim},
                         {"psnr_vs_float_db", dbJson(r.perView[v].vsFloat.psnrDb)},
                         {"ssim_vs_float", r.perView[v].vsFloat.ssim},
                         {"floor_psnr_db", dbJson(m.refs[v].floor.psnrDb)}});
    json["representations"].push_back({{"representation", r.run.name},
                                       {"record_bytes", r.run.viaCodec ? recordSize(r.run.repr) : kProbeFloats * 4},
                                       {"psnr_db", dbJson(r.psnr)},
                                       {"ssim", r.ssim},
                                       {"psnr_vs_float_db", dbJson(r.psnrFloat)},
                                       {"ssim_vs_float", r.ssimFloat},
                                       {"floor_psnr_db", dbJson(m.floorMean)},
                                       {"reference_psnr_db_estimate", dbJson(m.accuracyMean)},
                                       {"update_ms", m.updateMedian},
                                       {"decode_upload_ms", r.codecMs},
                                       {"raster_ms_per_view", r.msPerView},
                                       {"per_view", perView}});
  }
  json["validation_messages"] = s.context.validationMessages();
  return json;
}

std::string sceneTable(const SceneSetup& s, const SceneMetrics& m) {
  const SceneBenchOptions& o = s.o;
  const renderer::RasterOptions& ro = o.raster;
  std::string table = fmt::format(
      "scene bench: {} on {}, {} ({} views) of {}x{}{}, grid {}x{}x{}, {} spp per probe update, environment {}\n"
      "probe update: {:.1f} ms (median of {})\nreference: {} spp per view; noise floor {:.2f} dB (mean over views), "
      "reference itself ≈ {:.2f} dB\n",
      o.scene.name, s.context.deviceName(), o.views, s.views.size(), o.width, o.height,
      ro.samplesPerSide > 1 ? fmt::format(" ({}x{} raster samples per pixel)", ro.samplesPerSide, ro.samplesPerSide)
                            : std::string(),
      o.grid.dims[0], o.grid.dims[1], o.grid.dims[2], o.updater.samplesPerProbe,
      o.updater.environment ? o.updater.environment->name : "none", m.updateMedian, o.updates, o.referenceSpp,
      m.floorMean, m.accuracyMean);
  table += fmt::format("{:<6} {:>9} {:>7} {:>12} {:>11} {:>12} {:>11}\n", "repr", "PSNR dB", "SSIM", "vs float dB",
                       "SSIM float", "update ms", "ms/view");
  for (const ReprResult& r : m.reprs)
    table += fmt::format("{:<6} {:>9.2f} {:>7.4f} {:>12} {:>11.4f} {:>12.1f} {:>11.2f}\n", r.run.name, r.psnr, r.ssim,
                         std::isfinite(r.psnrFloat) ? fmt::format("{:.2f}", r.psnrFloat) : std::string("exact"),
                         r.ssimFloat, m.updateMedian, r.msPerView);
  if (s.views.size() > 1) {
    // Per view for the codec's most faithful representation: where in the set the method fails.
    const auto finite = [](double db) { return std::isfinite(db) ? db : INFINITY; };
    table += fmt::format("\nper view (l2): {:>6} {:>6} {:>9} {:>7} {:>9}\n", "column", "row", "PSNR dB", "SSIM",
                         "floor dB");
    const ReprResult& l2 = m.reprs[4];
    for (size_t v = 0; v < l2.perView.size(); ++v)
      table += fmt::format("{:>21} {:>6} {:>9.2f} {:>7.4f} {:>9.2f}\n", s.views[v].column, s.views[v].row,
                           finite(l2.perView[v].vsReference.psnrDb), l2.perView[v].vsReference.ssim,
                           finite(m.refs[v].floor.psnrDb));
  }
  return table;
}

// Mean PSNR against ms per view, one point per representation.
std::string sceneChart(const SceneBenchOptions& o, const SceneMetrics& m) {
  imaging::ChartSeries series{"representations", {}, false};
  for (const ReprResult& r : m.reprs) series.points.push_back({r.msPerView, r.psnr, r.run.name});
  imaging::ChartSpec chart;
  chart.title = fmt::format("{} at {}x{} ({}): PSNR against raster time per view", o.scene.name, o.width, o.height,
                            o.views);
  chart.xLabel = "raster ms per view (median)";
  chart.yLabel = fmt::format("PSNR against the {}-spp reference, dB (floor {:.1f})", o.referenceSpp, m.floorMean);
  chart.yFromZero = false;
  chart.footnote = o.command;
  return imaging::renderSvgChart(chart, {series});
}

}  // namespace

void checkSceneBenchOptions(const SceneBenchOptions& o) {
  renderer::ViewSetSpec spec;
  std::string error;
  if (!renderer::parseViewSet(o.views, spec, error)) throw std::invalid_argument("--views: " + error);
  if (o.width == 0 || o.height == 0) throw std::invalid_argument("--size: both sides must be at least 1");
  if (o.referenceSpp < 2)
    throw std::invalid_argument("--reference-spp: a reference is two halves of different seeds, so at least 2");
  const double samples = static_cast<double>(o.width) * o.height * spec.count() * o.referenceSpp;
  if (samples > kMaxReferenceSamples)
    throw std::invalid_argument(fmt::format(
        "--reference-spp {} for {} views of {}x{} is {:.3g} path samples, more than the {:.0e} a run may trace",
        o.referenceSpp, spec.count(), o.width, o.height, samples, kMaxReferenceSamples));
  if (o.updates == 0) throw std::invalid_argument("--updates: at least 1");
  if (o.repeats == 0) throw std::invalid_argument("--repeats: at least 1");
  renderer::checkRasterSize(o.width, o.height, o.raster);
  if (!o.imagesDir.empty() && std::filesystem::exists(o.imagesDir) && !std::filesystem::is_directory(o.imagesDir))
    throw std::invalid_argument("--images " + o.imagesDir + ": exists and is not a directory");
  if (!o.referenceCache.empty() && std::filesystem::exists(o.referenceCache) &&
      !std::filesystem::is_directory(o.referenceCache))
    throw std::invalid_argument("--reference-cache " + o.referenceCache + ": exists and is not a directory");
}

SceneBenchResult runSceneBench(const SceneBenchOptions& o) {
  checkSceneBenchOptions(o);
  renderer::ViewSetSpec spec;
  std::string error;
  renderer::parseViewSet(o.views, spec, error);
  const renderer::CameraView camera = renderer::CameraView::fromScene(o.scene);
  renderer::VulkanContext context(o.context);
  const SceneSetup s{o, context, renderer::makeViewSet(camera, spec, session::viewSetOptions(o.scene, o.width, o.height))};

  ReferenceCache cache(context, o.referenceCache, o.progress);
  SceneMetrics metrics;
  metrics.refs = sceneReferences(s, cache);
  const ProbeVolume volume = updateProbes(s, metrics);
  for (const Reference& r : metrics.refs) {
    metrics.floorMean += r.floor.psnrDb / static_cast<double>(metrics.refs.size());
    metrics.accuracyMean += r.accuracyDb / static_cast<double>(metrics.refs.size());
  }
  renderer::RasterOptions ro = o.raster;
  ro.environment = o.updater.environment;
  renderer::RasterRenderer raster(context, o.scene, o.width, o.height, ro);
  if (!o.imagesDir.empty()) {
    std::filesystem::create_directories(o.imagesDir);
    for (size_t v = 0; v < s.views.size(); ++v)
      writePng(fmt::format("{}/reference_v{:02}.png", o.imagesDir, v), metrics.refs[v].mean, o.exposure);
  }
  const std::vector<ReprRun> runs = {{"float", false},
                                     {"l1", true, Representation::L1},
                                     {"zh3h", true, Representation::Zh3Hallucinated},
                                     {"zh3", true, Representation::Zh3},
                                     {"l2", true, Representation::L2},
                                     {"fp16", true, Representation::Fp16}};
  std::vector<renderer::Image> floatImages;
  for (const ReprRun& run : runs) {
    metrics.reprs.push_back(measureRepresentation(s, raster, volume, run, metrics.refs, floatImages));
    sayProgress(o.progress, fmt::format("scene bench: {} {:.2f} dB ({})", run.name, metrics.reprs.back().psnr,
                                        describeFloor(metrics.refs[0])));
  }
  SceneBenchResult result;
  result.json = sceneJson(s, cache.dir(), metrics);
  result.table = sceneTable(s, metrics);
  result.svg = sceneChart(o, metrics);
  return result;
}

}  // namespace probecast::bench
