// `probecast demo`, the report: the final views against path-traced references, the charts,
// report.json and report.md, the printed summary (the suites and the video comparison it adds are
// in demo_suites.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <functional>

#include "commands.h"
#include "demo.h"
#include "progress.h"
#include "probecast/imaging/image_io.h"
#include "probecast/imaging/image_metrics.h"
#include "harness.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::app {
namespace {

// report.md without the suites' sections.
std::string reportMarkdown(const DemoOptions& o, const nlohmann::json& report, const std::string& device,
                           const std::vector<size_t>& viewsAboveScene) {
  std::string md = "# probecast demo\n\n";
  md += fmt::format("Produced by `{}` in {:.0f} s on {} (server and viewers on one machine, loopback gRPC).\n\n",
                    commandLine(), report["wall_seconds"].get<double>(), device);
  md += fmt::format(
      "A server path-traces {} into {}x{}x{} probes ({} samples per probe per update, median "
      "{:.0f} ms per update) while its light circles, and streams them as `{}`{}. A stereo headset "
      "and a {} light-field display subscribe over gRPC, re-render each time new lighting arrives "
      "(direct light locally at the light's current position, indirect light from the probes they "
      "hold), and after {:.0f} s the light stops, the probes settle for {} updates, and every view "
      "is compared with the reference path tracer ({} samples per pixel).\n\n",
      report["scene"].get<std::string>(), report["grid"][0].get<int>(), report["grid"][1].get<int>(),
      report["grid"][2].get<int>(), o.spp, report["update_ms_median"].get<double>(), o.repr,
      o.encoder.noiseScale > 0.0f
          ? fmt::format(" (a probe is re-sent only beyond {:g} standard errors of its noise{})", o.encoder.noiseScale,
                        o.encoder.refinementInterval > 0
                            ? fmt::format("; refinements of still probes wait for every {}th update",
                                          o.encoder.refinementInterval)
                            : std::string())
          : std::string(),
      o.lightField,
      report["stream_seconds"].get<double>(), o.settleUpdates, o.referenceSpp);
  md +=
      "| viewer | views | size | budget | frames | renders | ms/view | bytes/s while moving | PSNR dB (mean) | SSIM "
      "(mean) | holds the server's volume |\n";
  md += "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& v : report["viewers"])
    md += fmt::format(
        "| {} | {} | {}x{} | {} | {} | {} | {:.1f} | {:.0f} | {:.2f} | {:.4f} | {} |\n", v["name"].get<std::string>(),
        v["views"].get<std::string>(), v["size"][0].get<int>(), v["size"][1].get<int>(),
        v["budget_bytes_per_s"].get<uint64_t>() ? fmt::format("{} B/s", v["budget_bytes_per_s"].get<uint64_t>())
                                                : std::string("none"),
        v["frames_applied"].get<uint32_t>(), v["renders"].get<uint32_t>(), v["render_ms_per_view_median"].get<double>(),
        v["bytes_per_s_streaming"].get<double>(), v["psnr_db_mean"].get<double>(), v["ssim_mean"].get<double>(),
        v["converged_to_server_volume"].get<bool>() ? "yes" : "no");
  md += fmt::format(
      "\nPSNR and SSIM are computed after the same plain gamma 2.2 on both images, without "
      "clamping; the PNGs use a filmic tone map. Viewer pixels are anti-aliased ({}² raster "
      "samples per pixel, {}× MSAA), as each reference pixel averages its area. The reference has "
      "noise of its own: its two "
      "halves ({} samples per pixel each, different seeds) of the headset's left eye differ by "
      "{:.2f} dB PSNR, SSIM {:.4f}, so the reference itself is about {:.1f} dB from converged — the "
      "ceiling these figures can reach. Light-field views compared: the corners and the centre ({} "
      "in quilt order).\n\n",
      o.supersample, o.msaa, o.referenceSpp / 2, report["reference_noise_floor"]["psnr_db"].get<double>(),
      report["reference_noise_floor"]["ssim"].get<double>(),
      report["reference_noise_floor"]["reference_accuracy_db"].get<double>(),
      report["viewers"][1]["reference_views"].dump());
  if (!viewsAboveScene.empty())
    md += fmt::format(
        "Views {} look from above the scene's top (the light field's top rows): they see the "
        "outer face of the ceiling, which takes no probe light (every probe of its cells lies behind "
        "it), as in the reference.\n\n",
        nlohmann::json(viewsAboveScene).dump());
  md += "## While the scene moves\n\n![bytes per second per viewer](bandwidth.svg)\n\n";
  for (const auto& m : report["moments"])
    md += fmt::format("At {:.1f} s (server scene time {:.3f} s; headset drawn at {:.3f} s, display at {:.3f} s): "
                      "![stereo]({}) ![quilt]({})\n\n",
                      m["seconds"].get<double>(), m["scene_time"].get<double>(), m.value("stereo_scene_time", 0.0),
                      m.value("quilt_scene_time", 0.0), m.value("stereo", ""), m.value("quilt", ""));
  md += "## Against the reference\n\n![PSNR per view](psnr_per_view.svg)\n\n";
  md += "| | headset (stereo) | light-field quilt |\n|---|---|---|\n";
  md += "| probecast | ![](final_stereo.png) | ![](final_quilt.png) |\n";
  md += "| reference | ![](reference_stereo.png) | ![](reference_quilt.png) |\n";
  md += "| difference, view 0 | ![](difference_stereo_view0.png) | ![](difference_quilt_view0.png) |\n\n";
  md += "Data: [report.json](report.json).\n";
  return md;
}

// Every view of the headset; the corners and the centre of a light field (a reference costs
// seconds per view here).
std::vector<size_t> referenceViews(const DemoViewer& v) {
  const size_t n = v.viewer->views().size(), c = static_cast<size_t>(v.spec.columns);
  std::vector<size_t> views = {0};
  if (v.spec.kind != renderer::ViewSetSpec::Kind::Mono && v.spec.kind != renderer::ViewSetSpec::Kind::Stereo && n > 5) {
    for (size_t i : {c - 1, n / 2, n - c, n - 1}) views.push_back(i);
  } else {
    for (size_t i = 1; i < n; ++i) views.push_back(i);
  }
  std::sort(views.begin(), views.end());
  views.erase(std::unique(views.begin(), views.end()), views.end());
  return views;
}

// One viewer's final images at the frozen light against references from the cache (traced on a
// miss): the images, the metrics of each compared view, and view 0's reference with its noise floor.
struct ViewerComparison {
  std::vector<renderer::Image> references;  // black where no view was compared
  std::vector<double> psnr, ssim;
  imaging::ChartSeries series;
  bench::Reference first;
};

ViewerComparison compareViewer(const DemoOptions& o, const DemoRun& run, DemoViewer& v, const scene::Scene& finalScene,
                               const std::vector<size_t>& compared, bench::ReferenceCache& cache,
                               const std::function<void()>& done) {
  session::Viewer& viewer = *v.viewer;
  const std::vector<renderer::ViewInfo>& views = viewer.views();
  viewer.setShading(finalScene);
  viewer.render();
  const std::vector<renderer::Image>& images = viewer.images();
  ViewerComparison c;
  c.references.resize(views.size());
  for (renderer::Image& img : c.references) {
    img.width = v.width;
    img.height = v.height;
    img.rgb.assign(static_cast<size_t>(v.width) * v.height * 3, 0.0f);
  }
  c.series = {v.name + " (" + v.viewSet + ")", {}, true};
  bench::ReferenceRequest request;
  request.t = run.finalT;
  request.options.width = v.width;
  request.options.height = v.height;
  request.options.samplesPerPixel = o.referenceSpp;
  request.options.environment = o.sky;
  for (size_t i : compared) {
    request.camera = views[i].camera;
    bench::Reference reference = cache.get(finalScene, request);
    const imaging::ImageMetrics m = bench::compareChecked(images[i], reference.mean, fmt::format("{} view {}", v.name, i));
    c.psnr.push_back(m.psnrDb);
    c.ssim.push_back(m.ssim);
    c.series.points.push_back({static_cast<double>(i), m.psnrDb, fmt::format("view {}", i)});
    c.references[i] = reference.mean;
    if (i == compared.front()) c.first = std::move(reference);
    done();
  }
  return c;
}

double meanOf(const std::vector<double>& values) {
  double sum = 0.0;
  for (double x : values) sum += x;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

// A viewer's part of report.json.
nlohmann::json viewerReport(const DemoViewer& v, const DemoRun& run, const std::vector<size_t>& compared,
                            const ViewerComparison& c, const std::string& tag) {
  const session::Viewer& viewer = *v.viewer;
  const service::ClientStats st = viewer.clientStats();
  return {{"name", v.name},
          {"views", v.viewSet},
          {"view_count", viewer.views().size()},
          {"size", {v.width, v.height}},
          {"budget_bytes_per_s", v.budget},
          {"frames_applied", st.framesApplied},
          {"renders", viewer.stats().renders},
          {"render_ms_per_view_median", session::median(viewer.stats().renderMsPerView)},
          {"bytes_streaming", v.streamBytes},
          {"bytes_per_s_streaming", static_cast<double>(v.streamBytes) / run.streamSeconds},
          {"bytes_total", st.bytesReceived},
          {"converged_to_server_volume", v.converged},
          {"reference_views", compared},
          {"psnr_db", c.psnr},
          {"ssim", c.ssim},
          {"psnr_db_mean", meanOf(c.psnr)},
          {"ssim_mean", meanOf(c.ssim)},
          {"images",
           {{"final", "final_" + tag + ".png"},
            {"reference", "reference_" + tag + ".png"},
            {"difference_view0", "difference_" + tag + "_view0.png"}}}};
}

// Final images of every viewer at the frozen light, compared with references; the viewers' part
// of the report and the PSNR-per-view series. Views without a reference stay black in the reference quilt.
void compareWithReferences(const DemoOptions& o, DemoRun& run, const scene::Scene& finalScene, nlohmann::json& report,
                           std::vector<std::vector<size_t>>& compared, std::vector<imaging::ChartSeries>& psnrSeries) {
  uint32_t referencesDone = 0, referencesTotal = 0;
  for (const DemoViewer& v : run.viewers) {
    compared.push_back(referenceViews(v));
    referencesTotal += static_cast<uint32_t>(compared.back().size());
  }
  Progress progress("demo");
  const auto status = [&progress](const std::string& s) { progress.message(s); };
  // References are path-traced: on the server's device (the viewers' is raster-only).
  bench::ReferenceCache cache(*run.serverContext, o.referenceCache, status);
  report["reference_cache"] = cache.dir();
  const auto done = [&] {
    ++referencesDone;
    progress.update(static_cast<double>(referencesDone) / referencesTotal,
                    fmt::format("reference images {}/{}", referencesDone, referencesTotal));
  };
  for (size_t k = 0; k < run.viewers.size(); ++k) {
    DemoViewer& v = run.viewers[k];
    const ViewerComparison c = compareViewer(o, run, v, finalScene, compared[k], cache, done);
    if (k == 0)  // how far the reference itself is from converged: its two halves, view 0
      report["reference_noise_floor"] = {{"psnr_db", c.first.floor.psnrDb},
                                         {"ssim", c.first.floor.ssim},
                                         {"reference_accuracy_db", c.first.accuracyDb},
                                         {"from_cache", c.first.fromCache}};
    const std::string tag = k == 0 ? "stereo" : "quilt";
    const std::vector<renderer::Image>& images = v.viewer->images();
    writeViewerImages(o.out + "/final_" + tag, v, images);
    writeViewerImages(o.out + "/reference_" + tag, v, c.references);
    std::string error;
    if (!imaging::writeDifferencePng(o.out + "/difference_" + tag + "_view0.png", images[0].rgb, c.references[0].rgb,
                                     static_cast<int>(v.width), static_cast<int>(v.height), 0.25, error))
      throw std::runtime_error(error);
    report["viewers"].push_back(viewerReport(v, run, compared[k], c, tag));
    psnrSeries.push_back(c.series);
    v.viewer->stop();
  }
  progress.finish();
}

void writeCharts(const DemoOptions& o, const DemoRun& run, const std::vector<imaging::ChartSeries>& psnrSeries) {
  std::vector<imaging::ChartSeries> bandwidthSeries;
  for (const DemoViewer& v : run.viewers) bandwidthSeries.push_back({v.name, v.bandwidth, true});
  imaging::ChartSpec bw;
  bw.title = "Bytes per second received by each viewer while the light moves";
  bw.xLabel = "seconds";
  bw.yLabel = "bytes/s";
  bw.footnote = commandLine();
  writeTextFile(o.out + "/bandwidth.svg", imaging::renderSvgChart(bw, bandwidthSeries));
  imaging::ChartSpec q;
  q.title = "Each view against its reference (light frozen, probes settled)";
  q.xLabel = "view index (quilt order)";
  q.yLabel = "PSNR, dB";
  q.yFromZero = false;
  q.footnote = commandLine();
  writeTextFile(o.out + "/psnr_per_view.svg", imaging::renderSvgChart(q, psnrSeries));
}

}  // namespace

void writeDemoReport(const DemoOptions& o, DemoRun& run) {
  auto phaseStart = DemoClock::now();
  const scene::Scene finalScene = session::loadSceneOrThrow(o.scene, run.finalT);
  const session::ProducerStats producer = run.producer->stats();
  nlohmann::json report;
  report["command"] = commandLine();
  report["scene"] = run.scene0.name;
  report["grid"] = {run.grid.dims[0], run.grid.dims[1], run.grid.dims[2]};
  report["representation"] = o.repr;
  report["noise_scale"] = o.encoder.noiseScale;
  report["refinement_interval"] = o.encoder.refinementInterval;
  report["environment"] = !o.environment.file.empty() ? nlohmann::json(o.environment.file)
                          : !o.environment.sky.empty() ? nlohmann::json({{"sky", o.environment.sky}})
                                                       : nlohmann::json(nullptr);
  report["spp_per_update"] = o.spp;
  report["raster_samples_per_pixel"] = o.supersample * o.supersample;
  report["raster_msaa_samples"] = o.msaa;
  report["raster_texture_anisotropy"] = o.anisotropy;
  report["stream_seconds"] = run.streamSeconds;
  report["updates"] = producer.updates;
  report["update_ms_median"] = session::median(producer.updateMs);
  report["final_scene_time"] = run.finalT;
  report["moments"] = run.moments;
  report["server_device"] = run.serverContext->deviceName();
  report["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
  std::vector<std::vector<size_t>> compared;
  std::vector<imaging::ChartSeries> psnrSeries;
  compareWithReferences(o, run, finalScene, report, compared, psnrSeries);
  run.producer->shutdownServer();
  nlohmann::json& phases = run.phases;
  phases["references"] = secondsSince(phaseStart);
  report["phase_seconds"] = phases;
  writeCharts(o, run, psnrSeries);
  // Speed against accuracy across the pipeline, and the stability suite.
  std::string suites;
  if (!o.skipSuites) {
    suites = runSuites(o, o.out, finalScene, run.finalT, run.grid, phases);
    report["phase_seconds"] = phases;
  }
  if (o.video == "on") suites += runVideoComparison(o, run, o.out, report);
  const double wall = secondsSince(run.wallStart);
  report["wall_seconds"] = wall;
  writeTextFile(o.out + "/report.json", report.dump(2) + "\n");

  std::vector<size_t> above;  // light-field eyes above the scene: they see the ceiling's outer face
  for (size_t i : compared[1])
    if (run.viewers[1].viewer->views()[i].eye.y > finalScene.boundsMax.y) above.push_back(i);
  writeTextFile(o.out + "/report.md", reportMarkdown(o, report, run.serverContext->deviceName(), above) + suites);
  for (const auto& v : report["viewers"])
    fmt::print("demo: {:<20} {:>7} {:>4} frames, {:>8.0f} B/s while moving, PSNR {:.2f} dB, SSIM {:.4f}\n",
               v["name"].get<std::string>(), v["views"].get<std::string>(), v["frames_applied"].get<uint32_t>(),
               v["bytes_per_s_streaming"].get<double>(), v["psnr_db_mean"].get<double>(), v["ssim_mean"].get<double>());
  fmt::print("demo: wrote {}/report.md (and report.json, charts, images) in {:.0f} s\n", o.out, wall);
}

}  // namespace probecast::app
