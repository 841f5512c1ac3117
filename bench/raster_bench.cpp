#include "raster_bench.h"

#include "harness.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "probecast/imaging/image_metrics.h"
#include "probecast/codec/record.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/probe_interest.h"
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

RasterBenchResult runRasterBench(const RasterBenchOptions& o) {
  using Clock = std::chrono::steady_clock;
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  renderer::VulkanContext context(o.context);
  renderer::ProbeUpdater updater(context, o.scene, o.grid, o.updater);
  for (uint32_t u = 0; u < o.updates; ++u) updater.update();
  const ProbeVolume volume = updater.volume();
  say(fmt::format("raster bench: {} probe updates of {} probes done", o.updates, o.grid.count()));

  const renderer::CameraView camera = renderer::CameraView::fromScene(o.scene);
  ReferenceRequest request;
  request.camera = camera;
  request.options.width = o.width;
  request.options.height = o.height;
  request.options.samplesPerPixel = o.referenceSpp;
  request.options.environment = o.updater.environment;  // the same light as the probes
  ReferenceCache cache(context, o.referenceCache, o.progress);
  const Reference ref = cache.get(o.scene, request);

  nlohmann::json json;
  json["command"] = o.command;
  json["scene"] = o.scene.name;
  json["device"] = context.deviceName();
  json["size"] = {o.width, o.height};
  json["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  json["probe_updates"] = o.updates;
  json["reference_spp"] = o.referenceSpp;
  json["reference_key"] = ref.key;
  json["floor_psnr_db"] = ref.floor.psnrDb;
  json["reference_psnr_db_estimate"] = ref.accuracyDb;
  json["shadow_map_size"] = o.raster.shadowMapSize;
  json["shadow_cascades"] = o.raster.shadowCascades;
  json["area_lights"] = o.raster.areaLights.enabled;
  json["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
  std::string table = fmt::format("raster bench: {} at {}x{} on {}; reference {} spp, {}\n", o.scene.name, o.width,
                                  o.height, context.deviceName(), o.referenceSpp, describeFloor(ref));

  // Quality and mono speed per representation (float = the updater's probes without the codec).
  const std::vector<Representation> reprs = {{"float", false},
                                             {"l1", true, probecast::Representation::L1},
                                             {"zh3h", true, probecast::Representation::Zh3Hallucinated},
                                             {"zh3", true, probecast::Representation::Zh3},
                                             {"l2", true, probecast::Representation::L2},
                                             {"fp16", true, probecast::Representation::Fp16}};
  renderer::RasterOptions perView = o.raster;
  perView.environment = o.updater.environment;
  perView.passes = renderer::ViewPasses::PerView;
  renderer::RasterRenderer raster(context, o.scene, o.width, o.height, perView);
  imaging::ChartSeries qualitySeries{"representations (mono view)", {}, false};
  table += fmt::format("{:<6} {:>9} {:>7} {:>11}\n", "repr", "PSNR dB", "SSIM", "ms/view");
  for (const Representation& r : reprs) {
    raster.setProbes(r.viaCodec ? decodeAs(volume, r.repr, /*zh3PerPixel=*/true) : volume);
    const glm::mat4 vp = raster.viewProjection(camera);
    renderer::Image image = raster.render(vp, camera.position);  // warm-up (and shadow maps)
    if (!json.contains("shadow_ms")) json["shadow_ms"] = raster.timings().shadowMs;  // drawn once, here
    std::vector<double> ms;
    for (uint32_t k = 0; k < o.repeats; ++k) {
      const auto t0 = Clock::now();
      image = raster.render(vp, camera.position);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    const imaging::ImageMetrics m = compareChecked(image, ref.mean, r.name);
    const double msPerView = session::medianMidpoint(ms);
    json["representations"].push_back({{"representation", r.name},
                                       {"record_bytes", r.viaCodec ? recordSize(r.repr) : 108},
                                       {"psnr_db", m.psnrDb},
                                       {"ssim", m.ssim},
                                       {"ms_per_view", msPerView}});
    qualitySeries.points.push_back({msPerView, m.psnrDb, r.name});
    table += fmt::format("{:<6} {:>9.2f} {:>7.4f} {:>11.2f}\n", r.name, m.psnrDb, m.ssim, msPerView);
    say(fmt::format("raster bench: {} {:.2f} dB", r.name, m.psnrDb));
  }

  table += fmt::format("shadow maps ({} cascades per directional light): {:.2f} ms\n", o.raster.shadowCascades,
                       json["shadow_ms"].get<double>());
  // Visibility made by the first setProbes above (the same positions do not make it again).
  json["visibility"] = {{"on", raster.visibilityActive()},
                        {"build_render_ms", raster.timings().visibilityRenderMs},
                        {"build_moments_ms", raster.timings().visibilityMomentsMs},
                        {"bytes_per_probe", renderer::RasterRenderer::visibilityBytesPerProbe()}};
  table += fmt::format("visibility {}: made in {:.1f} ms (depth cubes) + {:.1f} ms (moments), {} bytes per probe\n",
                       raster.visibilityActive() ? "on" : "off", raster.timings().visibilityRenderMs,
                       raster.timings().visibilityMomentsMs, renderer::RasterRenderer::visibilityBytesPerProbe());

  // Speed per view set, both ways of drawing several views.
  const ProbeVolume l2 = decodeAs(volume, probecast::Representation::L2, /*zh3PerPixel=*/true);
  raster.setProbes(l2);
  renderer::RasterOptions multi = perView;
  multi.passes = renderer::ViewPasses::Multiview;
  renderer::RasterRenderer multiview(context, o.scene, o.width, o.height, multi);
  multiview.setProbes(l2);
  json["multiview_chunk"] = multiview.chunkSize();
  std::vector<imaging::ChartSeries> speedSeries = {{"one pass per view", {}, true}, {"multiview chunks", {}, true}};
  table += fmt::format("\n{:<8} {:>6} {:>16} {:>16}\n", "views", "count", "per-view ms/view", "multiview ms/view");
  const renderer::ViewSetOptions vo = session::viewSetOptions(o.scene, o.width, o.height);
  const session::SurfaceLighting lighting = session::surfaceLighting(o.scene, o.raster.areaLights);
  for (const std::string& name : o.viewSets) {
    renderer::ViewSetSpec spec;
    std::string error;
    if (!renderer::parseViewSet(name, spec, error)) throw std::invalid_argument(error);
    const auto views = renderer::makeViewSet(camera, spec, vo);
    nlohmann::json row{{"views", name}, {"count", views.size()}};
    double perViewMs[2] = {0, 0};
    for (int way = 0; way < 2; ++way) {
      renderer::RasterRenderer& r = way == 0 ? raster : multiview;
      r.renderViews(views);  // warm-up
      std::vector<double> ms;
      for (uint32_t k = 0; k < o.repeats; ++k) {
        r.renderViews(views);
        ms.push_back(r.timings().viewsMs);
      }
      const double set = session::medianMidpoint(ms);
      perViewMs[way] = set / static_cast<double>(views.size());
      row[way == 0 ? "per_view_pass" : "multiview"] = {{"ms_per_view_set", set}, {"ms_per_view", perViewMs[way]}};
      speedSeries[static_cast<size_t>(way)].points.push_back({static_cast<double>(views.size()), perViewMs[way], ""});
    }
    row["shadow_ms"] = raster.timings().shadowMs;
    row["area_shadow_ms"] = raster.timings().areaShadowMs;
    // What the same views cost a producer with the noise rule on the CPU (probe_interest.h, as
    // ProbeProducer uses it): their surfaces when views change, their weights every update.
    {
      const std::vector<View> seen = session::spreadViews(session::priorityViews(views), session::kFootprintViews);
      const glm::uvec2 size = session::footprintSampleSize(seen.size());
      std::vector<double> surfacesMs, directMs, weightsMs;
      std::vector<session::ViewSample> samples;
      const auto since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
      for (uint32_t k = 0; k < o.repeats; ++k) {
        auto t0 = Clock::now();
        samples = session::sampleViewSurfaces(o.scene, o.grid, volume.active, volume.offsets, seen, size.x, size.y);
        surfacesMs.push_back(since(t0));
        t0 = Clock::now();
        const std::vector<glm::vec3> direct = session::sampleDirectLight(o.scene, samples, lighting);
        directMs.push_back(since(t0));
        t0 = Clock::now();
        const std::vector<float> w = session::probeViewSensitivity(samples, direct, lighting, volume.probes, o.grid.count());
        weightsMs.push_back(since(t0));
      }
      row["producer_view_weights"] = {{"views_sampled", seen.size()},
                                      {"samples", samples.size()},
                                      {"surfaces_ms_median", session::medianMidpoint(surfacesMs)},
                                      {"direct_light_ms_median", session::medianMidpoint(directMs)},
                                      {"weights_ms_median", session::medianMidpoint(weightsMs)}};
    }
    json["view_sets"].push_back(row);
    table += fmt::format("{:<8} {:>6} {:>16.2f} {:>16.2f}\n", name, views.size(), perViewMs[0], perViewMs[1]);
    say(fmt::format("raster bench: {} done", name));
  }
  table += fmt::format("multiview chunk: {} views per pass\n", multiview.chunkSize());
  table += "producer view weights on the CPU (up to 16 views), ms: surfaces (when the views change), direct light "
           "(when the lights move), weights (every update)\n";
  for (const nlohmann::json& row : json["view_sets"])
    table += fmt::format("  {:<8} {:>8.2f} {:>8.2f} {:>8.2f}\n", row["views"].get<std::string>(),
                         row["producer_view_weights"]["surfaces_ms_median"].get<double>(),
                         row["producer_view_weights"]["direct_light_ms_median"].get<double>(),
                         row["producer_view_weights"]["weights_ms_median"].get<double>());
  table += fmt::format("shadow maps: punctual {:.2f} ms, {} client area lights {:.2f} ms (drawn once per plan)\n",
                       raster.timings().shadowMs, raster.areaLights().lights.size(), raster.timings().areaShadowMs);

  table += timeVolumeUpdates(raster, o, json);
  json["validation_messages"] = context.validationMessages();

  imaging::ChartSpec spec;
  spec.title =
      fmt::format("Raster client, {} at {}x{}: image quality against time per view", o.scene.name, o.width, o.height);
  spec.xLabel = "ms per view (mono, median)";
  spec.yLabel = "PSNR against the reference, dB";
  spec.yFromZero = false;
  spec.footnote = o.command;
  RasterBenchResult result;
  result.svg = imaging::renderSvgChart(spec, {qualitySeries});
  imaging::ChartSpec views;
  views.title =
      fmt::format("Raster client, {} at {}x{}: time per view against views per set", o.scene.name, o.width, o.height);
  views.xLabel = "views in the set";
  views.yLabel = "ms per view (median)";
  views.logX = true;
  views.footnote = o.command;
  result.svgViews = imaging::renderSvgChart(views, speedSeries);
  result.json = std::move(json);
  result.table = std::move(table);
  return result;
}

}  // namespace probecast::bench
