#include "raster_bench.h"

#include "harness.h"
#include "raster_parts.h"

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

using namespace rasters;

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
