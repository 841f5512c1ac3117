#include "raster_bench.h"

#include "harness.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "probecast/imaging/image_metrics.h"
#include "probecast/codec/record.h"
#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {
namespace {

struct Representation {
  std::string name;
  bool viaCodec = false;
  probecast::Representation repr = probecast::Representation::L2;
};

}  // namespace

namespace {

// What one volume update costs the client (validate, fill inactive probes, upload), for the
// volume sizes of the demo and of a large hall; one probe in eight inactive. Returns table rows.
std::string timeVolumeUpdates(renderer::RasterRenderer& raster, const RasterBenchOptions& o, nlohmann::json& json) {
  using Clock = std::chrono::steady_clock;
  std::string table = fmt::format("\n{:<10} {:>8} {:>16}\n", "volume", "probes", "ms per update");
  for (const auto& dims : o.uploadGrids) {
    const glm::vec3 lo = o.scene.boundsMin, hi = o.scene.boundsMax;
    ProbeVolume v = makeProbeVolume(ProbeGrid{{dims.x, dims.y, dims.z}, {{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}}});
    const size_t n = v.count(), f = kProbeFloats;
    for (size_t p = 0; p < n; ++p) {
      v.active[p] = p % 8 != 3;
      for (size_t c = 0; c < f; ++c)
        v.probes[p * f + c] = (c % 9 == 0 ? 1.0f : 0.1f) * static_cast<float>((p * 31 + c * 7) % 17) / 17.0f;
    }
    raster.setProbes(v);  // warm-up (first allocation)
    std::vector<double> ms;
    for (uint32_t k = 0; k < 4 * o.repeats; ++k) {
      v.probes[(k % n) * f] += 0.01f;  // a new volume each time
      const auto t0 = Clock::now();
      raster.setProbes(v);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    const double median = session::medianMidpoint(ms);
    json["volume_upload"].push_back({{"grid", {dims.x, dims.y, dims.z}}, {"probes", n}, {"ms_median", median}});
    table += fmt::format("{:<10} {:>8} {:>16.3f}\n", fmt::format("{}x{}x{}", dims.x, dims.y, dims.z), n, median);
  }
  return table;
}

}  // namespace

namespace {

using Clock = std::chrono::steady_clock;

// One representation's mono view against the reference, and its speed.
struct Quality {
  Representation r;
  imaging::ImageMetrics metrics;
  double msPerView = 0;
};

// What the same views cost a producer with the noise rule on the CPU (probe_interest.h, as
// ProbeProducer uses it): their surfaces when views change, their weights every update.
struct ProducerWeights {
  size_t viewsSampled = 0, samples = 0;
  double surfacesMs = 0, directMs = 0, weightsMs = 0;  // medians
};

// One view set, drawn both ways: one pass per view, and multiview chunks.
struct ViewSetSpeed {
  std::string name;
  size_t count = 0;
  double setMs[2] = {0, 0}, perViewMs[2] = {0, 0};  // [way]
  double shadowMs = 0, areaShadowMs = 0;
  ProducerWeights producer;
};

// What the bench measures: filled by the phases below, written by the report functions.
struct RasterMetrics {
  double firstShadowMs = 0;  // drawn once, with the first representation
  std::vector<Quality> quality;
  bool visibilityOn = false;
  double visibilityRenderMs = 0, visibilityMomentsMs = 0;
  uint32_t multiviewChunk = 0;
  std::vector<ViewSetSpeed> viewSets;
  double shadowMs = 0, areaShadowMs = 0;  // after the view sets
  size_t areaLights = 0;
};

const std::vector<Representation>& representations() {
  static const std::vector<Representation> reprs = {{"float", false},
                                                    {"l1", true, probecast::Representation::L1},
                                                    {"zh3h", true, probecast::Representation::Zh3Hallucinated},
                                                    {"zh3", true, probecast::Representation::Zh3},
                                                    {"l2", true, probecast::Representation::L2},
                                                    {"fp16", true, probecast::Representation::Fp16}};
  return reprs;
}

// Quality and mono speed per representation (float = the updater's probes without the codec).
void measureQuality(const RasterBenchOptions& o, renderer::RasterRenderer& raster, const ProbeVolume& volume,
                    const Reference& ref, RasterMetrics& metrics) {
  const renderer::CameraView camera = renderer::CameraView::fromScene(o.scene);
  for (const Representation& r : representations()) {
    raster.setProbes(r.viaCodec ? decodeAs(volume, r.repr, /*zh3PerPixel=*/true) : volume);
    const glm::mat4 vp = raster.viewProjection(camera);
    renderer::Image image = raster.render(vp, camera.position);  // warm-up (and shadow maps)
    if (metrics.quality.empty()) metrics.firstShadowMs = raster.timings().shadowMs;
    std::vector<double> ms;
    for (uint32_t k = 0; k < o.repeats; ++k) {
      const auto t0 = Clock::now();
      image = raster.render(vp, camera.position);
      ms.push_back(millisecondsSince(t0));
    }
    metrics.quality.push_back({r, compareChecked(image, ref.mean, r.name), session::medianMidpoint(ms)});
    sayProgress(o.progress, fmt::format("raster bench: {} {:.2f} dB", r.name, metrics.quality.back().metrics.psnrDb));
  }
  // Visibility made by the first setProbes above (the same positions do not make it again).
  metrics.visibilityOn = raster.visibilityActive();
  metrics.visibilityRenderMs = raster.timings().visibilityRenderMs;
  metrics.visibilityMomentsMs = raster.timings().visibilityMomentsMs;
}

ProducerWeights measureProducerWeights(const RasterBenchOptions& o, const std::vector<renderer::ViewInfo>& views,
                                       const ProbeVolume& volume, const renderer::SurfaceLighting& lighting) {
  const std::vector<View> seen = renderer::spreadViews(session::priorityViews(views), renderer::kFootprintViews);
  const glm::uvec2 size = renderer::footprintSampleSize(seen.size());
  std::vector<double> surfacesMs, directMs, weightsMs;
  std::vector<renderer::ViewSample> samples;
  for (uint32_t k = 0; k < o.repeats; ++k) {
    auto t0 = Clock::now();
    samples = renderer::sampleViewSurfaces(o.scene, o.grid, volume.active, volume.offsets, seen, size.x, size.y);
    surfacesMs.push_back(millisecondsSince(t0));
    t0 = Clock::now();
    const std::vector<glm::vec3> direct = renderer::sampleDirectLight(o.scene, samples, lighting);
    directMs.push_back(millisecondsSince(t0));
    t0 = Clock::now();
    const std::vector<float> w =
        renderer::probeViewSensitivity(samples, direct, lighting, volume.probes, o.grid.count());
    weightsMs.push_back(millisecondsSince(t0));
  }
  return {seen.size(), samples.size(), session::medianMidpoint(surfacesMs), session::medianMidpoint(directMs),
          session::medianMidpoint(weightsMs)};
}

// Speed per view set, both ways of drawing several views (`renderers`: per view, multiview).
ViewSetSpeed measureViewSet(const RasterBenchOptions& o, const std::string& name, renderer::RasterRenderer* renderers[2],
                            const ProbeVolume& volume, const renderer::SurfaceLighting& lighting) {
  renderer::ViewSetSpec spec;
  std::string error;
  if (!renderer::parseViewSet(name, spec, error)) throw std::invalid_argument(error);
  const auto views = renderer::makeViewSet(renderer::CameraView::fromScene(o.scene), spec,
                                           session::viewSetOptions(o.scene, o.width, o.height));
  ViewSetSpeed speed;
  speed.name = name;
  speed.count = views.size();
  for (int way = 0; way < 2; ++way) {
    renderer::RasterRenderer& r = *renderers[way];
    r.renderViews(views);  // warm-up
    std::vector<double> ms;
    for (uint32_t k = 0; k < o.repeats; ++k) {
      r.renderViews(views);
      ms.push_back(r.timings().viewsMs);
    }
    speed.setMs[way] = session::medianMidpoint(ms);
    speed.perViewMs[way] = speed.setMs[way] / static_cast<double>(views.size());
  }
  speed.shadowMs = renderers[0]->timings().shadowMs;
  speed.areaShadowMs = renderers[0]->timings().areaShadowMs;
  speed.producer = measureProducerWeights(o, views, volume, lighting);
  return speed;
}

nlohmann::json rasterJson(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                          const RasterMetrics& m) {
  nlohmann::json json;
  json["command"] = o.command;
  json["scene"] = o.scene.name;
  json["device"] = device;
  json["size"] = {o.width, o.height};
  json["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  json["probe_updates"] = o.updates;
  json["reference_spp"] = o.referenceSpp;
  json["reference_key"] = ref.key;
  json["floor_psnr_db"] = ref.floor.psnrDb;
  json["reference_psnr_db_estimate"] = ref.accuracyDb;
  json["shadow_map_size"] = o.raster.shadowMapSize;
  json["shadow_cascades"] = o.raster.shadowCascades;
  json["supersample"] = o.raster.samplesPerSide;  // ms per view are for the supersampled size
  json["msaa_samples"] = o.raster.msaaSamples;
  json["texture_anisotropy"] = o.raster.anisotropy;
  json["area_lights"] = o.raster.areaLights.enabled;
  json["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
  if (!m.quality.empty()) json["shadow_ms"] = m.firstShadowMs;
  for (const Quality& q : m.quality)
    json["representations"].push_back({{"representation", q.r.name},
                                       {"record_bytes", q.r.viaCodec ? recordSize(q.r.repr) : 108},
                                       {"psnr_db", q.metrics.psnrDb},
                                       {"ssim", q.metrics.ssim},
                                       {"ms_per_view", q.msPerView}});
  json["visibility"] = {{"on", m.visibilityOn},
                        {"build_render_ms", m.visibilityRenderMs},
                        {"build_moments_ms", m.visibilityMomentsMs},
                        {"bytes_per_probe", renderer::RasterRenderer::visibilityBytesPerProbe()}};
  json["multiview_chunk"] = m.multiviewChunk;
  for (const ViewSetSpeed& v : m.viewSets)
    json["view_sets"].push_back(
        {{"views", v.name},
         {"count", v.count},
         {"per_view_pass", {{"ms_per_view_set", v.setMs[0]}, {"ms_per_view", v.perViewMs[0]}}},
         {"multiview", {{"ms_per_view_set", v.setMs[1]}, {"ms_per_view", v.perViewMs[1]}}},
         {"shadow_ms", v.shadowMs},
         {"area_shadow_ms", v.areaShadowMs},
         {"producer_view_weights", {{"views_sampled", v.producer.viewsSampled},
                                    {"samples", v.producer.samples},
                                    {"surfaces_ms_median", v.producer.surfacesMs},
                                    {"direct_light_ms_median", v.producer.directMs},
                                    {"weights_ms_median", v.producer.weightsMs}}}});
  return json;
}

// The table, up to the volume updates (timeVolumeUpdates adds their rows).
std::string rasterTable(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                        const RasterMetrics& m) {
  std::string table = fmt::format("raster bench: {} at {}x{} ({}x{} supersampled, MSAA {}) on {}; reference {} spp, {}\n",
                                  o.scene.name, o.width, o.height, o.raster.samplesPerSide, o.raster.samplesPerSide,
                                  o.raster.msaaSamples, device, o.referenceSpp, describeFloor(ref));
  table += fmt::format("{:<6} {:>9} {:>7} {:>11}\n", "repr", "PSNR dB", "SSIM", "ms/view");
  for (const Quality& q : m.quality)
    table += fmt::format("{:<6} {:>9.2f} {:>7.4f} {:>11.2f}\n", q.r.name, q.metrics.psnrDb, q.metrics.ssim, q.msPerView);
  table += fmt::format("shadow maps ({} cascades per directional light): {:.2f} ms\n", o.raster.shadowCascades,
                       m.firstShadowMs);
  table += fmt::format("visibility {}: made in {:.1f} ms (depth cubes) + {:.1f} ms (moments), {} bytes per probe\n",
                       m.visibilityOn ? "on" : "off", m.visibilityRenderMs, m.visibilityMomentsMs,
                       renderer::RasterRenderer::visibilityBytesPerProbe());
  table += fmt::format("\n{:<8} {:>6} {:>16} {:>16}\n", "views", "count", "per-view ms/view", "multiview ms/view");
  for (const ViewSetSpeed& v : m.viewSets)
    table += fmt::format("{:<8} {:>6} {:>16.2f} {:>16.2f}\n", v.name, v.count, v.perViewMs[0], v.perViewMs[1]);
  table += fmt::format("multiview chunk: {} views per pass\n", m.multiviewChunk);
  table += "producer view weights on the CPU (up to 16 views), ms: surfaces (when the views change), direct light "
           "(when the lights move), weights (every update)\n";
  for (const ViewSetSpeed& v : m.viewSets)
    table += fmt::format("  {:<8} {:>8.2f} {:>8.2f} {:>8.2f}\n", v.name, v.producer.surfacesMs, v.producer.directMs,
                         v.producer.weightsMs);
  table += fmt::format("shadow maps: punctual {:.2f} ms, {} client area lights {:.2f} ms (drawn once per plan)\n",
                       m.shadowMs, m.areaLights, m.areaShadowMs);
  return table;
}

// PSNR against ms per view per representation; ms per view against views per set, both ways.
void rasterCharts(const RasterBenchOptions& o, const RasterMetrics& m, RasterBenchResult& result) {
  imaging::ChartSeries qualitySeries{"representations (mono view)", {}, false};
  for (const Quality& q : m.quality) qualitySeries.points.push_back({q.msPerView, q.metrics.psnrDb, q.r.name});
  std::vector<imaging::ChartSeries> speedSeries = {{"one pass per view", {}, true}, {"multiview chunks", {}, true}};
  for (const ViewSetSpeed& v : m.viewSets)
    for (size_t way = 0; way < 2; ++way)
      speedSeries[way].points.push_back({static_cast<double>(v.count), v.perViewMs[way], ""});
  imaging::ChartSpec spec;
  spec.title =
      fmt::format("Raster client, {} at {}x{}: image quality against time per view", o.scene.name, o.width, o.height);
  spec.xLabel = "ms per view (mono, median)";
  spec.yLabel = "PSNR against the reference, dB";
  spec.yFromZero = false;
  spec.footnote = o.command;
  result.svg = imaging::renderSvgChart(spec, {qualitySeries});
  imaging::ChartSpec views;
  views.title =
      fmt::format("Raster client, {} at {}x{}: time per view against views per set", o.scene.name, o.width, o.height);
  views.xLabel = "views in the set";
  views.yLabel = "ms per view (median)";
  views.logX = true;
  views.footnote = o.command;
  result.svgViews = imaging::renderSvgChart(views, speedSeries);
}

}  // namespace

RasterBenchResult runRasterBench(const RasterBenchOptions& o) {
  renderer::VulkanContext context(o.context);
  renderer::ProbeUpdater updater(context, o.scene, o.grid, o.updater);
  for (uint32_t u = 0; u < o.updates; ++u) updater.update();
  const ProbeVolume volume = updater.volume();
  sayProgress(o.progress, fmt::format("raster bench: {} probe updates of {} probes done", o.updates, o.grid.count()));
  ReferenceCache cache(context, o.referenceCache, o.progress);
  const Reference ref = cache.get(o.scene, referenceRequest(renderer::CameraView::fromScene(o.scene), o.width, o.height,
                                                            o.referenceSpp, o.updater.environment));  // the probes' light

  RasterMetrics metrics;
  renderer::RasterOptions perView = o.raster;
  perView.environment = o.updater.environment;
  perView.passes = renderer::ViewPasses::PerView;
  renderer::RasterRenderer raster(context, o.scene, o.width, o.height, perView);
  measureQuality(o, raster, volume, ref, metrics);

  const ProbeVolume l2 = decodeAs(volume, probecast::Representation::L2, /*zh3PerPixel=*/true);
  raster.setProbes(l2);
  renderer::RasterOptions multi = perView;
  multi.passes = renderer::ViewPasses::Multiview;
  renderer::RasterRenderer multiview(context, o.scene, o.width, o.height, multi);
  multiview.setProbes(l2);
  metrics.multiviewChunk = multiview.chunkSize();
  const renderer::SurfaceLighting lighting = renderer::surfaceLighting(o.scene, o.raster.areaLights);
  renderer::RasterRenderer* renderers[2] = {&raster, &multiview};
  for (const std::string& name : o.viewSets) {
    metrics.viewSets.push_back(measureViewSet(o, name, renderers, volume, lighting));
    sayProgress(o.progress, fmt::format("raster bench: {} done", name));
  }
  metrics.shadowMs = raster.timings().shadowMs;
  metrics.areaShadowMs = raster.timings().areaShadowMs;
  metrics.areaLights = raster.areaLights().lights.size();

  RasterBenchResult result;
  result.json = rasterJson(o, context.deviceName(), ref, metrics);
  result.table = rasterTable(o, context.deviceName(), ref, metrics);
  result.table += timeVolumeUpdates(raster, o, result.json);
  result.json["validation_messages"] = context.validationMessages();
  rasterCharts(o, metrics, result);
  return result;
}

}  // namespace probecast::bench
