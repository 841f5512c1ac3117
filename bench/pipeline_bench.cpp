#include "pipeline_bench.h"

#include "harness.h"

#include <algorithm>
#include <numeric>

#include <fmt/format.h>

#include "probecast/imaging/image_metrics.h"
#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {

std::vector<size_t> paretoFront(const std::vector<ParetoPoint>& points) {
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return points[a].cost != points[b].cost ? points[a].cost < points[b].cost : points[a].quality > points[b].quality;
  });
  std::vector<size_t> front;
  double best = -std::numeric_limits<double>::infinity();
  for (size_t i : order)
    if (points[i].quality > best) {
      front.push_back(i);
      best = points[i].quality;
    }
  return front;
}

namespace {

struct Point {
  std::string label;
  double cost = 0;
  double psnr = 0;
  double ssim = 0;
};

// A chart of PSNR against cost: every point, and the Pareto front joined.
std::string paretoChart(const std::string& title, const std::string& xLabel, bool logX, const std::vector<Point>& pts,
                        const std::string& command, nlohmann::json& json) {
  std::vector<ParetoPoint> pp;
  for (const Point& p : pts) pp.push_back({p.cost, p.psnr});
  const std::vector<size_t> front = paretoFront(pp);
  imaging::ChartSeries all{"configurations", {}, false}, best{"Pareto front", {}, true};
  for (size_t i = 0; i < pts.size(); ++i) {
    const bool onFront = std::find(front.begin(), front.end(), i) != front.end();
    all.points.push_back({pts[i].cost, pts[i].psnr, onFront ? "" : pts[i].label});
    json.push_back({{"label", pts[i].label},
                    {"cost", pts[i].cost},
                    {"psnr_db", pts[i].psnr},
                    {"ssim", pts[i].ssim},
                    {"pareto", onFront}});
  }
  for (size_t i : front) best.points.push_back({pts[i].cost, pts[i].psnr, pts[i].label});
  imaging::ChartSpec spec;
  spec.title = title;
  spec.xLabel = xLabel;
  spec.yLabel = "PSNR against the reference, dB";
  spec.logX = logX;
  spec.yFromZero = false;
  spec.footnote = command;
  return imaging::renderSvgChart(spec, {all, best});
}

}  // namespace

namespace {

// What the bench measures, one point per configuration: PSNR against each stage's cost.
struct PipelineMetrics {
  std::vector<Point> updateCost;      // ms per update, samples per probe × bounces
  std::vector<Point> representation;  // bytes per probe record
  std::vector<Point> wireBytes;       // bytes per second, representation × dead-zone
};

// Every phase scores a volume the same way: its raster view against the reference at t.
class Scorer {
 public:
  Scorer(renderer::VulkanContext& context, const scene::Scene& scene, const PipelineBenchOptions& o,
         const Reference& reference)
      : camera_(renderer::CameraView::fromScene(scene)),
        reference_(reference),
        raster_(context, scene, o.width, o.height, rasterOptions(o)) {}

  void score(const ProbeVolume& v, Point& p) {
    raster_.setProbes(v);
    const renderer::Image img = raster_.render(raster_.viewProjection(camera_), camera_.position);
    const imaging::ImageMetrics m = compareChecked(img, reference_.mean, "pipeline bench");
    p.psnr = m.psnrDb;
    p.ssim = m.ssim;
  }

 private:
  static renderer::RasterOptions rasterOptions(const PipelineBenchOptions& o) {
    renderer::RasterOptions ro = singleSampleRaster();
    ro.environment = o.environment;
    return ro;
  }
  renderer::CameraView camera_;
  const Reference& reference_;
  renderer::RasterRenderer raster_;
};

// (b) Update cost: samples per probe × bounces, the light still at t.
std::vector<Point> measureUpdateCost(renderer::VulkanContext& context, const scene::Scene& scene,
                                     const PipelineBenchOptions& o, Scorer& scorer) {
  std::vector<Point> points;
  for (uint32_t b : o.bounces)
    for (uint32_t spp : o.spps) {
      renderer::UpdaterOptions uo;
      uo.samplesPerProbe = spp;
      uo.maxBounces = b;
      uo.environment = o.environment;
      renderer::ProbeUpdater u(context, scene, o.grid, uo);
      std::vector<double> ms;
      for (uint32_t k = 0; k < o.updates; ++k) ms.push_back(u.update().milliseconds);
      Point p{fmt::format("{} spp, {} bounce{}", spp, b, b == 1 ? "" : "s"), session::median(ms)};
      scorer.score(u.volume(), p);
      points.push_back(p);
      sayProgress(o.progress, fmt::format("pipeline bench: {}: {:.1f} ms/update, {:.2f} dB", p.label, p.cost, p.psnr));
    }
  return points;
}

// (c) Representation: one well-converged volume through each record type.
std::vector<Point> measureRepresentations(renderer::VulkanContext& context, const scene::Scene& scene,
                                          const PipelineBenchOptions& o, Scorer& scorer) {
  renderer::UpdaterOptions good;
  good.samplesPerProbe = 128;
  good.environment = o.environment;
  renderer::ProbeUpdater converged(context, scene, o.grid, good);
  for (int k = 0; k < 8; ++k) converged.update();
  const ProbeVolume volume = converged.volume();
  std::vector<Point> points;
  for (Representation repr : kAllRepresentations) {
    Point p{representationName(repr), static_cast<double>(recordSize(repr))};
    scorer.score(decodeAs(volume, repr, /*zh3PerPixel=*/true), p);
    points.push_back(p);
  }
  Point floatPoint{"float", 108.0};
  scorer.score(volume, floatPoint);
  points.push_back(floatPoint);
  return points;
}

// A moving-light sequence ending at t.
std::vector<ProbeVolume> traceMovingFrames(renderer::VulkanContext& context, const PipelineBenchOptions& o) {
  const auto sceneAt = [&](float t) { return session::loadSceneOrThrow(o.sceneSpec, t); };
  std::vector<ProbeVolume> frames;
  renderer::UpdaterOptions uo;
  uo.samplesPerProbe = 64;
  uo.minBlendWeight = 0.25f;
  uo.environment = o.environment;
  renderer::ProbeUpdater u(context, sceneAt(o.t), o.grid, uo);
  for (uint32_t f = 0; f < o.streamFrames; ++f) {
    const float t = o.t - 0.004f * static_cast<float>(o.streamFrames - 1 - f);
    u.setScene(sceneAt(t - std::floor(t)));
    u.update();
    frames.push_back(u.volume());
  }
  sayProgress(o.progress, fmt::format("pipeline bench: {} moving-light frames traced", o.streamFrames));
  return frames;
}

// (a) Wire bytes: the sequence encoded per representation × dead-zone; bytes per second at `hz`,
// quality of what a subscriber holds at the end.
std::vector<Point> measureWireBytes(const std::vector<ProbeVolume>& frames, const PipelineBenchOptions& o,
                                    Scorer& scorer) {
  std::vector<Point> points;
  StreamLayout layout = streamLayoutFor(o.grid, Representation::L1, 4);
  for (Representation repr : kAllRepresentations)
    for (int dz : o.deadzones) {
      layout.repr = repr;
      EncoderOptions eo;
      eo.deadzone = dz;
      StreamEncoder encoder(layout, eo);
      StreamDecoder decoder(layout);
      decoder.setZh3PerPixel(true);
      std::vector<uint8_t> bytes;
      uint64_t total = 0;
      for (size_t f = 0; f < frames.size(); ++f) {
        encoder.update(frames[f].probes.data(), frames[f].active.data());
        if (f == 0) encoder.writeKeyframeFrame(bytes);
        else encoder.writeChangedFrame(bytes);
        if (f > 0) total += bytes.size();  // steady state: the first (key)frame is a join, not a rate
        if (decoder.apply(bytes.data(), bytes.size()) != CodecStatus::Ok)
          throw std::runtime_error("pipeline bench: decoder refused its own stream");
      }
      ProbeVolume held;
      decoder.copyVolume(frames.back().grid.bounds, held);
      Point p{fmt::format("{} dz{}", representationName(repr), dz),
              static_cast<double>(total) / static_cast<double>(frames.size() - 1) * o.hz};
      scorer.score(held, p);
      points.push_back(p);
    }
  return points;
}

// The charts (with each point in the JSON) and the table's sections.
void reportPipeline(const PipelineBenchOptions& o, const PipelineMetrics& m, PipelineBenchResult& r) {
  nlohmann::json& j = r.json;
  r.svgUpdate = paretoChart(fmt::format("PSNR against probe update time ({} updates each)", o.updates),
                            "ms per update (median)", true, m.updateCost, o.command, j["update_cost"]);
  r.svgRepr = paretoChart("PSNR against bytes per probe (representation)", "bytes per probe record", true,
                          m.representation, o.command, j["representation"]);
  r.svgBytes = paretoChart(fmt::format("PSNR against wire bytes/s while the light moves ({:g} updates/s)", o.hz),
                           "bytes per second (one subscriber)", true, m.wireBytes, o.command, j["wire_bytes"]);
  const auto section = [&](const std::string& name, const std::string& unit, const nlohmann::json& rows) {
    r.table += fmt::format("\n{:<22} {:>14} {:>9} {:>7}  Pareto\n", name, unit, "PSNR dB", "SSIM");
    for (const auto& row : rows)
      r.table += fmt::format("{:<22} {:>14.1f} {:>9.2f} {:>7.4f}  {}\n", row["label"].get<std::string>(),
                             row["cost"].get<double>(), row["psnr_db"].get<double>(), row["ssim"].get<double>(),
                             row["pareto"].get<bool>() ? "*" : "");
  };
  section("update", "ms/update", j["update_cost"]);
  section("representation", "bytes/probe", j["representation"]);
  section("stream", "bytes/s", j["wire_bytes"]);
}

}  // namespace

PipelineBenchResult runPipelineBench(const PipelineBenchOptions& o) {
  renderer::VulkanContext context(o.context);
  const scene::Scene finalScene = session::loadSceneOrThrow(o.sceneSpec, o.t);
  sayProgress(o.progress, fmt::format("pipeline bench: reference ({} spp)", o.referenceSpp));
  ReferenceCache cache(context, o.referenceCache, o.progress);
  const Reference reference = cache.get(finalScene, referenceRequest(renderer::CameraView::fromScene(finalScene), o.width,
                                                                     o.height, o.referenceSpp, o.environment, o.t));
  Scorer scorer(context, finalScene, o, reference);

  PipelineBenchResult r;
  nlohmann::json& j = r.json;
  j["command"] = o.command;
  j["codec_format_version"] = kFormatVersion;
  j["scene"] = finalScene.name;
  j["device"] = context.deviceName();
  j["size"] = {o.width, o.height};
  j["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  j["reference_spp"] = o.referenceSpp;
  j["reference_key"] = reference.key;
  j["floor_psnr_db"] = reference.floor.psnrDb;
  j["reference_psnr_db_estimate"] = reference.accuracyDb;
  j["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
  r.table = fmt::format("pipeline bench: {} at {}x{}, {}x{}x{} probes, on {}\n", finalScene.name, o.width, o.height,
                        o.grid.dims[0], o.grid.dims[1], o.grid.dims[2], context.deviceName());

  PipelineMetrics metrics;
  metrics.updateCost = measureUpdateCost(context, finalScene, o, scorer);
  metrics.representation = measureRepresentations(context, finalScene, o, scorer);
  metrics.wireBytes = measureWireBytes(traceMovingFrames(context, o), o, scorer);
  reportPipeline(o, metrics, r);
  return r;
}

}  // namespace probecast::bench
