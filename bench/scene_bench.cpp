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

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  renderer::ViewSetSpec spec;
  std::string error;
  renderer::parseViewSet(o.views, spec, error);
  const renderer::CameraView camera = renderer::CameraView::fromScene(o.scene);
  const std::vector<renderer::ViewInfo> views =
      renderer::makeViewSet(camera, spec, session::viewSetOptions(o.scene, o.width, o.height));

  renderer::VulkanContext context(o.context);
  // References first: they are the slow part, and a cache hit makes re-runs cheap.
  ReferenceCache cache(context, o.referenceCache, o.progress);
  std::vector<Reference> refs;
  for (size_t v = 0; v < views.size(); ++v) {
    ReferenceRequest request;
    request.t = o.t;
    request.camera = views[v].camera;
    request.options.width = o.width;
    request.options.height = o.height;
    request.options.samplesPerPixel = o.referenceSpp;
    request.options.maxBounces = o.referenceBounces;
    request.options.seed = o.referenceSeed;
    request.options.environment = o.updater.environment;
    say(fmt::format("scene bench: reference for view {}/{}", v + 1, views.size()));
    refs.push_back(cache.get(o.scene, request));
  }

  renderer::ProbeUpdater updater(context, o.scene, o.grid, o.updater);
  std::vector<double> updateMs;
  for (uint32_t u = 0; u < o.updates; ++u) {
    const auto t0 = Clock::now();
    updater.update();
    updateMs.push_back(msSince(t0));
    say(fmt::format("scene bench: probe update {}/{} ({:.0f} ms)", u + 1, o.updates, updateMs.back()));
  }
  const double updateMedian = session::medianMidpoint(updateMs);
  const ProbeVolume volume = updater.volume();

  renderer::RasterOptions ro = o.raster;
  ro.environment = o.updater.environment;
  renderer::RasterRenderer raster(context, o.scene, o.width, o.height, ro);
  const auto render = [&] { return raster.renderViews(views); };
  if (!o.imagesDir.empty()) {
    std::filesystem::create_directories(o.imagesDir);
    for (size_t v = 0; v < views.size(); ++v)
      writePng(fmt::format("{}/reference_v{:02}.png", o.imagesDir, v), refs[v].mean, o.exposure);
  }

  nlohmann::json json;
  json["command"] = o.command;
  json["scene"] = o.scene.name;
  json["device"] = context.deviceName();
  json["size"] = {o.width, o.height};
  json["supersample"] = o.raster.samplesPerSide;  // raster ms per view are for the supersampled size
  json["views"] = o.views;
  json["view_count"] = views.size();
  json["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  json["bounds"] = {o.grid.bounds.min[0], o.grid.bounds.min[1], o.grid.bounds.min[2],
                    o.grid.bounds.max[0], o.grid.bounds.max[1], o.grid.bounds.max[2]};
  json["samples_per_probe"] = o.updater.samplesPerProbe;
  json["probe_updates"] = o.updates;
  json["update_ms_all"] = updateMs;
  json["environment"] = o.updater.environment ? o.updater.environment->name : "none";
  json["visibility"] = o.raster.visibility;
  json["area_lights"] = o.raster.areaLights.enabled;
  json["reference_cache"] = cache.dir();
  json["metric"] =
      "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2, per view, then the mean over views; the reference is "
      "the mean of two half-references of different seeds; noise floor = PSNR(half A, half B); the reference's own "
      "accuracy ~ floor + 6.02 dB";
  nlohmann::json refJson = nlohmann::json::array();
  for (size_t v = 0; v < views.size(); ++v)
    refJson.push_back({{"view", v},
                       {"key", refs[v].key},
                       {"spp", o.referenceSpp},
                       {"from_cache", refs[v].fromCache},
                       {"seconds", refs[v].seconds},
                       {"floor_psnr_db", dbJson(refs[v].floor.psnrDb)},
                       {"floor_ssim", refs[v].floor.ssim},
                       {"reference_psnr_db_estimate", dbJson(refs[v].accuracyDb)}});
  json["references"] = refJson;

  double floorMean = 0.0, accuracyMean = 0.0;
  for (const Reference& r : refs) {
    floorMean += r.floor.psnrDb / static_cast<double>(refs.size());
    accuracyMean += r.accuracyDb / static_cast<double>(refs.size());
  }
  std::string table = fmt::format(
      "scene bench: {} on {}, {} ({} views) of {}x{}{}, grid {}x{}x{}, {} spp per probe update, environment {}\n"
      "probe update: {:.1f} ms (median of {})\nreference: {} spp per view; noise floor {:.2f} dB (mean over views), "
      "reference itself ≈ {:.2f} dB\n",
      o.scene.name, context.deviceName(), o.views, views.size(), o.width, o.height,
      ro.samplesPerSide > 1 ? fmt::format(" ({}x{} raster samples per pixel)", ro.samplesPerSide, ro.samplesPerSide)
                            : std::string(),
      o.grid.dims[0], o.grid.dims[1],
      o.grid.dims[2], o.updater.samplesPerProbe, json["environment"].get<std::string>(), updateMedian, o.updates,
      o.referenceSpp, floorMean, accuracyMean);
  table += fmt::format("{:<6} {:>9} {:>7} {:>12} {:>11} {:>12} {:>11}\n", "repr", "PSNR dB", "SSIM", "vs float dB",
                       "SSIM float", "update ms", "ms/view");

  const std::vector<ReprRun> runs = {{"float", false},
                                     {"l1", true, Representation::L1},
                                     {"zh3h", true, Representation::Zh3Hallucinated},
                                     {"zh3", true, Representation::Zh3},
                                     {"l2", true, Representation::L2},
                                     {"fp16", true, Representation::Fp16}};
  std::vector<renderer::Image> floatImages;
  imaging::ChartSeries series{"representations", {}, false};
  for (const ReprRun& run : runs) {
    const auto c0 = Clock::now();
    raster.setProbes(run.viaCodec ? decodeAs(volume, run.repr, /*zh3PerPixel=*/true) : volume);
    const double codecMs = msSince(c0);
    std::vector<renderer::Image> images = render();  // warm-up (and shadow maps)
    std::vector<double> ms;
    for (uint32_t k = 0; k < o.repeats; ++k) {
      images = render();
      ms.push_back(raster.timings().viewsMs / static_cast<double>(views.size()));
    }
    if (!run.viaCodec) floatImages = images;
    const double msPerView = session::medianMidpoint(ms);
    nlohmann::json perView = nlohmann::json::array();
    double psnr = 0, ssim = 0, psnrFloat = 0, ssimFloat = 0;
    const double n = static_cast<double>(views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      const Comparison c = compareView(images[v], refs[v], floatImages[v], fmt::format("{} view {}", run.name, v));
      psnr += c.vsReference.psnrDb / n;
      ssim += c.vsReference.ssim / n;
      psnrFloat += c.vsFloat.psnrDb / n;
      ssimFloat += c.vsFloat.ssim / n;
      perView.push_back({{"view", v},
                         {"column", views[v].column},
                         {"row", views[v].row},
                         {"psnr_db", dbJson(c.vsReference.psnrDb)},
                         {"ssim", c.vsReference.ssim},
                         {"psnr_vs_float_db", dbJson(c.vsFloat.psnrDb)},
                         {"ssim_vs_float", c.vsFloat.ssim},
                         {"floor_psnr_db", dbJson(refs[v].floor.psnrDb)}});
      if (!o.imagesDir.empty()) {
        writePng(fmt::format("{}/{}_v{:02}.png", o.imagesDir, run.name, v), images[v], o.exposure);
        // Luminance difference after gamma against the reference, 0.1 shown as full red.
        std::string diffError;
        if (!imaging::writeDifferencePng(fmt::format("{}/{}_v{:02}_difference.png", o.imagesDir, run.name, v),
                                         images[v].rgb, refs[v].mean.rgb, static_cast<int>(o.width),
                                         static_cast<int>(o.height), 0.1, diffError))
          throw std::runtime_error(diffError);
      }
    }
    json["representations"].push_back({{"representation", run.name},
                                       {"record_bytes", run.viaCodec ? recordSize(run.repr) : kProbeFloats * 4},
                                       {"psnr_db", dbJson(psnr)},
                                       {"ssim", ssim},
                                       {"psnr_vs_float_db", dbJson(psnrFloat)},
                                       {"ssim_vs_float", ssimFloat},
                                       {"floor_psnr_db", dbJson(floorMean)},
                                       {"reference_psnr_db_estimate", dbJson(accuracyMean)},
                                       {"update_ms", updateMedian},
                                       {"decode_upload_ms", codecMs},
                                       {"raster_ms_per_view", msPerView},
                                       {"per_view", perView}});
    series.points.push_back({msPerView, psnr, run.name});
    table += fmt::format("{:<6} {:>9.2f} {:>7.4f} {:>12} {:>11.4f} {:>12.1f} {:>11.2f}\n", run.name, psnr, ssim,
                         std::isfinite(psnrFloat) ? fmt::format("{:.2f}", psnrFloat) : std::string("exact"), ssimFloat,
                         updateMedian, msPerView);
    say(fmt::format("scene bench: {} {:.2f} dB ({})", run.name, psnr, describeFloor(refs[0])));
  }
  if (views.size() > 1) {
    // Per view for the codec's most faithful representation: where in the set the method fails.
    table += fmt::format("\nper view (l2): {:>6} {:>6} {:>9} {:>7} {:>9}\n", "column", "row", "PSNR dB", "SSIM",
                         "floor dB");
    for (const auto& pv : json["representations"][4]["per_view"])
      table += fmt::format("{:>21} {:>6} {:>9.2f} {:>7.4f} {:>9.2f}\n", pv["column"].get<int>(), pv["row"].get<int>(),
                           pv["psnr_db"].is_null() ? INFINITY : pv["psnr_db"].get<double>(), pv["ssim"].get<double>(),
                           pv["floor_psnr_db"].is_null() ? INFINITY : pv["floor_psnr_db"].get<double>());
  }
  json["validation_messages"] = context.validationMessages();

  imaging::ChartSpec chart;
  chart.title = fmt::format("{} at {}x{} ({}): PSNR against raster time per view", o.scene.name, o.width, o.height,
                            o.views);
  chart.xLabel = "raster ms per view (median)";
  chart.yLabel = fmt::format("PSNR against the {}-spp reference, dB (floor {:.1f})", o.referenceSpp, floorMean);
  chart.yFromZero = false;
  chart.footnote = o.command;
  SceneBenchResult result;
  result.svg = imaging::renderSvgChart(chart, {series});
  result.json = std::move(json);
  result.table = std::move(table);
  return result;
}

}  // namespace probecast::bench
