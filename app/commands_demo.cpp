// `probecast demo`: the product end to end on one machine. A server traces builtin:cornell with a
// moving light and streams it over loopback gRPC; a stereo headset and a light-field display
// subscribe, re-render whenever new lighting arrives (direct light at the current light position,
// indirect light from the probes they hold), and the run ends with both compared against the
// reference path tracer. Writes images, charts, report.md and report.json to --out.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "commands.h"
#include "probecast/imaging/image_io.h"
#include "probecast/imaging/image_metrics.h"
#include "pipeline_bench.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "scene_options.h"
#include "stability.h"
#include "probecast/imaging/svg_chart.h"
#include "view_support.h"

namespace probecast::app {
namespace {

using Clock = std::chrono::steady_clock;

struct DemoOptions {
  std::string out = "out";
  std::string scene = "builtin:cornell";
  double seconds = 24.0;        // streaming with the light moving
  double turnsPerMinute = 1.5;  // light speed (builtin scenes move it once around per unit of t)
  uint32_t spp = 64;            // updater samples per probe per update
  std::vector<uint32_t> grid{8, 8, 8};
  std::string repr = "zh3";
  std::string lightField = "lf:5x5";
  uint32_t settleUpdates = 24;  // updates with the light frozen before the comparison
  uint32_t referenceSpp = 256;
  uint64_t lightFieldBudget = 6 * 1024;  // bytes/s: the display sits on a thin link
  bool skipSuites = false;               // no pipeline benchmark or stability suite in the report
};

struct Viewer {
  std::string name, viewSet;
  uint32_t width = 0, height = 0;
  uint64_t budget = 0;
  renderer::ViewSetSpec spec;
  std::vector<renderer::ViewInfo> views;
  std::unique_ptr<service::ProbeClient> client;
  std::unique_ptr<renderer::RasterRenderer> raster;
  std::vector<renderer::Image> images;
  uint32_t framesSeen = 0, renders = 0;
  std::vector<double> renderMsPerView;
  std::vector<imaging::ChartPoint> bandwidth;  // (seconds, bytes/s over the last interval)
  std::vector<size_t> referenceViews;        // the views compared with the reference tracer
  uint64_t lastBytes = 0;
};

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

scene::Scene sceneAt(const std::string& spec, float t) {
  scene::Scene s;
  std::string error;
  if (!scene::loadScene(spec, t, s, error)) throw std::runtime_error(error);
  return s;
}

void writePng(const std::string& path, const renderer::Image& img) {
  std::string error;
  if (!imaging::writePngPreview(path, img.rgb, static_cast<int>(img.width), static_cast<int>(img.height), 1.0f, error))
    throw std::runtime_error(error);
}

// A viewer's current images on disk: a stereo pair side by side, or a light-field quilt.
void writeViewerImages(const std::string& prefix, const Viewer& v, const std::vector<renderer::Image>& images) {
  writePng(prefix + ".png", renderer::composeQuilt(images, v.views, v.spec.columns, v.spec.rows));
}

std::string progressBar(double fraction) {
  const int width = 30, filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * width);
  return "[" + std::string(static_cast<size_t>(filled), '#') + std::string(static_cast<size_t>(width - filled), ' ') +
         "]";
}

// The pipeline benchmark (small) and the stability suite, written next to the report; returns
// their report sections.
std::string runSuites(const DemoOptions& o, const std::string& dir, const scene::Scene& finalScene, float finalT,
                      const ProbeGrid& grid, nlohmann::json& phases) {
  const auto status = [](const std::string& s) { fmt::print(stderr, "\rdemo: {:<90}", s.substr(0, 90)); };
  auto phaseStart = Clock::now();
  bench::PipelineBenchOptions po;
  po.sceneSpec = o.scene;
  po.scene = finalScene;
  po.t = finalT;
  po.grid = grid;
  po.width = 128;
  po.height = 80;
  po.referenceSpp = 2 * o.referenceSpp;
  po.spps = {32, 128};
  po.bounces = {1, 4};
  po.deadzones = {0, 4, 16};
  po.streamFrames = 16;
  po.updates = 3;
  po.command = commandLine() + " (pipeline part)";
  po.progress = status;
  const bench::PipelineBenchResult pr = bench::runPipelineBench(po);
  writeTextFile(dir + "/pipeline.json", pr.json.dump(2) + "\n");
  writeTextFile(dir + "/pipeline_bytes.svg", pr.svgBytes);
  writeTextFile(dir + "/pipeline_update.svg", pr.svgUpdate);
  writeTextFile(dir + "/pipeline_repr.svg", pr.svgRepr);
  phases["pipeline"] = secondsSince(phaseStart);
  phaseStart = Clock::now();
  bench::StabilityOptions so;
  so.command = commandLine() + " (stability part)";
  so.progress = status;
  const bench::StabilityResult sr = bench::runStabilitySuite(so);
  writeTextFile(dir + "/stability.json", sr.json.dump(2) + "\n");
  phases["stability"] = secondsSince(phaseStart);
  fmt::print(stderr, "\n");
  return "\n## Speed against accuracy across the pipeline\n\n"
         "Same scene, same view (the light frozen where the demo stopped it), one run; the Pareto front of "
         "each chart is joined. Data: [pipeline.json](pipeline.json).\n\n"
         "![PSNR against wire bytes](pipeline_bytes.svg)\n\n![PSNR against update time](pipeline_update.svg)"
         "\n\n![PSNR against representation](pipeline_repr.svg)\n\n```\n" +
         pr.table +
         "```\n"
         "\n## Stability: where probe lighting fails, measured\n\nEach case is also a test "
         "(`ctest -L stability`). Data: [stability.json](stability.json).\n\n" +
         sr.markdown;
}

// report.md without the suites' sections.
std::string reportMarkdown(const DemoOptions& o, const nlohmann::json& report, const std::string& device,
                           const std::vector<size_t>& viewsAboveScene) {
  std::string md = "# probecast demo\n\n";
  md += fmt::format("Produced by `{}` in {:.0f} s on {} (server and viewers on one machine, loopback gRPC).\n\n",
                    commandLine(), report["wall_seconds"].get<double>(), device);
  md += fmt::format(
      "A server path-traces {} into {}x{}x{} probes ({} samples per probe per update, median "
      "{:.0f} ms per update) while its light circles, and streams them as `{}`. A stereo headset "
      "and a {} light-field display subscribe over gRPC, re-render each time new lighting arrives "
      "(direct light locally at the light's current position, indirect light from the probes they "
      "hold), and after {:.0f} s the light stops, the probes settle for {} updates, and every view "
      "is compared with the reference path tracer ({} samples per pixel).\n\n",
      report["scene"].get<std::string>(), report["grid"][0].get<int>(), report["grid"][1].get<int>(),
      report["grid"][2].get<int>(), o.spp, report["update_ms_median"].get<double>(), o.repr, o.lightField,
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
      "clamping; the PNGs use a filmic tone map. The reference has noise of its own: two "
      "references of the headset's left eye with different seeds differ by {:.2f} dB PSNR, SSIM "
      "{:.4f} — the ceiling these figures can reach. Light-field views compared: the corners and "
      "the centre ({} in quilt order).\n\n",
      report["reference_noise_floor"]["psnr_db"].get<double>(), report["reference_noise_floor"]["ssim"].get<double>(),
      report["viewers"][1]["reference_views"].dump());
  if (!viewsAboveScene.empty())
    md += fmt::format(
        "Views {} look from above the scene's top (the light field's top rows): they see the "
        "outer face of the ceiling lit by the probes inside — a leak the reference does not have, "
        "and why they score lowest.\n\n",
        nlohmann::json(viewsAboveScene).dump());
  md += "## While the light moves\n\n![bytes per second per viewer](bandwidth.svg)\n\n";
  for (const auto& m : report["moments"])
    md += fmt::format("At {:.1f} s (t = {:.3f}): ![stereo]({}) ![quilt]({})\n\n", m["seconds"].get<double>(),
                      m["t"].get<double>(), m.value("stereo", ""), m.value("quilt", ""));
  md += "## Against the reference\n\n![PSNR per view](psnr_per_view.svg)\n\n";
  md += "| | headset (stereo) | light-field quilt |\n|---|---|---|\n";
  md += "| probecast | ![](final_stereo.png) | ![](final_quilt.png) |\n";
  md += "| reference | ![](reference_stereo.png) | ![](reference_quilt.png) |\n";
  md += "| difference, view 0 | ![](difference_stereo_view0.png) | ![](difference_quilt_view0.png) |\n\n";
  md += "Data: [report.json](report.json).\n";
  return md;
}

}  // namespace

void addDemoCommand(CLI::App& app, int& exitCode) {
  CLI::App* demo = app.add_subcommand("demo", "server + stereo and light-field viewers over loopback; writes out/");
  auto o = std::make_shared<DemoOptions>();
  demo->add_option("--out", o->out, "output folder");
  demo->add_option("--scene", o->scene, "scene the server lights (built-in scenes animate their light)");
  demo->add_option("--seconds", o->seconds, "streaming time with the light moving")->check(CLI::Range(1.0, 3600.0));
  demo->add_option("--spp", o->spp, "updater samples per probe per update")->check(CLI::Range(1, 1 << 16));
  demo->add_option("--grid", o->grid, "probes along X,Y,Z")->delimiter(',')->expected(3)->check(CLI::Range(2, 64));
  demo->add_option("--repr", o->repr, "representation streamed")
      ->check(CLI::IsMember({"l1", "zh3h", "zh3", "l2", "fp16"}));
  demo->add_option("--light-field", o->lightField, "the light-field display's view set (lf:NxM or lfh:NxM)");
  demo->add_option("--settle-updates", o->settleUpdates, "updates with the light frozen before the comparison")
      ->check(CLI::Range(1, 10000));
  demo->add_option("--reference-spp", o->referenceSpp, "samples per pixel of the reference images")
      ->check(CLI::Range(1, 1 << 16));
  demo->add_flag("--skip-suites", o->skipSuites, "leave the pipeline benchmark and the stability suite out");
  demo->callback([o, &exitCode] {
    namespace fs = std::filesystem;
    const auto wallStart = Clock::now();
    fs::create_directories(o->out);
    const std::string dir = o->out;

    // The server: its own Vulkan device, the updater, the hub and gRPC on a free loopback port.
    const scene::Scene scene0 = sceneAt(o->scene, 0.0f);
    const bool animated = o->scene.rfind("builtin:", 0) == 0;  // built-in scenes move their light with t
    GridOptions gridOptions;
    gridOptions.dims = o->grid;
    const ProbeGrid grid = gridOptions.resolve(scene0);
    renderer::VulkanContext serverContext{renderer::ContextOptions{}};
    renderer::UpdaterOptions uo;
    uo.samplesPerProbe = o->spp;
    renderer::ProbeUpdater updater(serverContext, scene0, grid, uo);
    service::HubConfig hc = service::hubConfigFor(grid, *parseRepresentation(o->repr), 4);
    hc.encoder.deadzone = 1;
    service::ProbeHub hub(hc);
    service::ServerConfig sc;
    sc.plaintext = true;  // loopback only
    std::random_device rd;
    sc.token = fmt::format("demo-{:08x}{:08x}", rd(), rd());
    service::ProbeServer server(sc, hub);
    fmt::print(
        "demo: server on 127.0.0.1:{} lighting {} ({}x{}x{} probes, {} spp/update, {}), light moving for {:.0f} s\n",
        server.port(), scene0.name, grid.dims[0], grid.dims[1], grid.dims[2], o->spp, o->repr, o->seconds);

    // Animation: t follows wall time while streaming, then freezes for the comparison.
    const auto animStart = Clock::now();
    const double tRate = o->turnsPerMinute / 60.0;
    std::atomic<bool> frozen{false}, stop{false};
    std::atomic<float> frozenT{0.0f};
    const auto tNow = [&] {
      return frozen ? frozenT.load() : static_cast<float>(std::fmod(tRate * secondsSince(animStart), 1.0));
    };
    std::atomic<uint32_t> updates{0}, settled{0};
    std::mutex updateMsMutex;
    std::vector<double> updateMs;
    std::thread producer([&] {
      try {
        while (!stop) {
          const bool wasFrozen = frozen;
          if (animated) updater.setScene(sceneAt(o->scene, tNow()));
          const renderer::UpdateStats st = updater.update();
          hub.publish(updater.volume());
          ++updates;
          if (wasFrozen) ++settled;
          std::lock_guard<std::mutex> lock(updateMsMutex);
          updateMs.push_back(st.milliseconds);
        }
      } catch (const std::exception& e) {
        fmt::print(stderr, "demo: updater stopped: {}\n", e.what());
        stop = true;
      }
    });

    // The viewers: their own Vulkan device (a headset and a display are other machines).
    renderer::VulkanContext viewerContext{renderer::ContextOptions{}};
    std::vector<Viewer> viewers(2);
    viewers[0].name = "headset";
    viewers[0].viewSet = "stereo";
    viewers[0].width = 192;
    viewers[0].height = 120;
    viewers[1].name = "light-field display";
    viewers[1].viewSet = o->lightField;
    viewers[1].width = 128;
    viewers[1].height = 80;
    viewers[1].budget = o->lightFieldBudget;
    for (Viewer& v : viewers) {
      std::string error;
      if (!renderer::parseViewSet(v.viewSet, v.spec, error)) throw std::runtime_error(error);
      v.views = renderer::makeViewSet(renderer::CameraView::fromScene(scene0), v.spec,
                                      viewSetOptions(scene0, v.width, v.height));
      service::ClientConfig cc;
      cc.address = fmt::format("127.0.0.1:{}", server.port());
      cc.token = sc.token;
      cc.name = v.name;
      cc.budgetBytesPerSecond = v.budget;
      cc.zh3PerPixel = true;
      v.client = std::make_unique<service::ProbeClient>(cc);
      v.client->setViews(priorityViews(v.views));
      v.client->start();
      v.raster = std::make_unique<renderer::RasterRenderer>(viewerContext, scene0, v.width, v.height);
    }
    const auto renderIfNew = [&](Viewer& v, bool force) {
      const service::ClientStats st = v.client->stats();
      if (!force && st.framesApplied == v.framesSeen) return false;
      service::VolumeSnapshot snap;
      if (!v.client->snapshot(snap)) return false;
      v.framesSeen = snap.framesApplied;
      if (animated) v.raster->setShading(sceneAt(o->scene, tNow()));  // direct light is local: the light now
      v.raster->setProbes(snap.volume);
      v.images = v.raster->renderViews(v.views);
      v.renderMsPerView.push_back(v.raster->timings().viewsMs / static_cast<double>(v.views.size()));
      ++v.renders;
      return true;
    };

    // Streaming with the light moving: re-render as lighting arrives, snapshots at three moments.
    nlohmann::json moments = nlohmann::json::array();
    const double moment[3] = {o->seconds / 3.0, 2.0 * o->seconds / 3.0, o->seconds};
    int nextMoment = 0;
    double lastSample = 0.0;
    while (!stop) {
      const double now = secondsSince(animStart);
      bool rendered = false;
      for (Viewer& v : viewers) rendered |= renderIfNew(v, false);
      if (now - lastSample >= 1.0) {
        for (Viewer& v : viewers) {
          const uint64_t bytes = v.client->stats().bytesReceived;
          v.bandwidth.push_back({now, static_cast<double>(bytes - v.lastBytes) / (now - lastSample), ""});
          v.lastBytes = bytes;
        }
        lastSample = now;
      }
      if (nextMoment < 3 && now >= moment[nextMoment]) {
        nlohmann::json m{{"seconds", now}, {"t", tNow()}};
        for (size_t k = 0; k < viewers.size(); ++k)
          if (!viewers[k].images.empty()) {
            const std::string file = fmt::format("moment{}_{}.png", nextMoment + 1, k == 0 ? "stereo" : "quilt");
            writeViewerImages(dir + "/" + file.substr(0, file.size() - 4), viewers[k], viewers[k].images);
            m[k == 0 ? "stereo" : "quilt"] = file;
          }
        moments.push_back(m);
        ++nextMoment;
      }
      fmt::print(stderr,
                 "\rdemo: {} {:4.1f}/{:.0f} s  updates {:4}  headset {:4} frames {:4} renders  display {:4} frames "
                 "{:4} renders",
                 progressBar(now / o->seconds), std::min(now, o->seconds), o->seconds, updates.load(),
                 viewers[0].framesSeen, viewers[0].renders, viewers[1].framesSeen, viewers[1].renders);
      if (now >= o->seconds) break;
      if (!rendered) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    fmt::print(stderr, "\n");
    const double streamSeconds = secondsSince(animStart);
    std::vector<uint64_t> streamBytes;
    for (Viewer& v : viewers) streamBytes.push_back(v.client->stats().bytesReceived);

    // Freeze the light, let the probes settle, wait for both viewers to hold the server's volume.
    nlohmann::json phases;
    phases["setup"] = std::chrono::duration<double>(animStart - wallStart).count();
    phases["streaming"] = streamSeconds;
    auto phaseStart = Clock::now();
    frozenT = tNow();
    frozen = true;
    const float finalT = frozenT;
    while (!stop && settled < o->settleUpdates) {
      fmt::print(stderr, "\rdemo: {} light frozen at t = {:.3f}, settling {}/{} updates",
                 progressBar(static_cast<double>(settled) / o->settleUpdates), finalT, settled.load(),
                 o->settleUpdates);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    stop = true;
    producer.join();
    fmt::print(stderr, "\n");
    phases["settling"] = secondsSince(phaseStart);
    phaseStart = Clock::now();
    const ProbeVolume serverVolume = hub.reconstruction();
    std::vector<bool> converged(viewers.size(), false);
    const auto waitStart = Clock::now();
    while (secondsSince(waitStart) < 30.0 &&
           !std::all_of(converged.begin(), converged.end(), [](bool c) { return c; })) {
      for (size_t k = 0; k < viewers.size(); ++k) {
        service::VolumeSnapshot snap;
        if (!viewers[k].client->snapshot(snap)) continue;
        const ProbeVolume& held = snap.volume;
        converged[k] = held.active == serverVolume.active && held.probes.size() == serverVolume.probes.size();
        // A zh3h viewer holds L1 only (it hallucinates per pixel): compare the 12 floats it holds.
        for (size_t i = 0; converged[k] && i < held.probes.size(); ++i)
          converged[k] = (held.zh3PerPixel && i % kProbeFloats >= 12) || held.probes[i] == serverVolume.probes[i];
        if (!converged[k]) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }

    phases["converging"] = secondsSince(phaseStart);
    phaseStart = Clock::now();
    // Final images and references for every view, at the frozen light.
    const scene::Scene finalScene = sceneAt(o->scene, finalT);
    nlohmann::json report;
    report["command"] = commandLine();
    report["scene"] = scene0.name;
    report["grid"] = {grid.dims[0], grid.dims[1], grid.dims[2]};
    report["representation"] = o->repr;
    report["spp_per_update"] = o->spp;
    report["stream_seconds"] = streamSeconds;
    report["updates"] = updates.load();
    {
      std::lock_guard<std::mutex> lock(updateMsMutex);
      report["update_ms_median"] = median(updateMs);
    }
    report["final_t"] = finalT;
    report["moments"] = moments;
    report["server_device"] = serverContext.deviceName();
    report["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
    std::vector<imaging::ChartSeries> bandwidthSeries, psnrSeries;
    // Every view of the headset; the corners and the centre of a light field (a reference costs
    // seconds per view here). Views without a reference stay black in the reference quilt.
    uint32_t referencesDone = 0, referencesTotal = 1;  // + the noise floor
    for (Viewer& v : viewers) {
      const size_t n = v.views.size(), c = static_cast<size_t>(v.spec.columns);
      v.referenceViews = {0};
      if (v.spec.kind != renderer::ViewSetSpec::Kind::Mono && v.spec.kind != renderer::ViewSetSpec::Kind::Stereo &&
          n > 5) {
        for (size_t i : {c - 1, n / 2, n - c, n - 1}) v.referenceViews.push_back(i);
      } else {
        for (size_t i = 1; i < n; ++i) v.referenceViews.push_back(i);
      }
      std::sort(v.referenceViews.begin(), v.referenceViews.end());
      v.referenceViews.erase(std::unique(v.referenceViews.begin(), v.referenceViews.end()), v.referenceViews.end());
      referencesTotal += static_cast<uint32_t>(v.referenceViews.size());
    }
    const auto progressReferences = [&] {
      ++referencesDone;
      fmt::print(stderr, "\rdemo: {} reference images {}/{}",
                 progressBar(static_cast<double>(referencesDone) / referencesTotal), referencesDone, referencesTotal);
    };
    for (size_t k = 0; k < viewers.size(); ++k) {
      Viewer& v = viewers[k];
      v.raster->setShading(finalScene);
      renderIfNew(v, true);
      std::vector<renderer::Image> references(v.views.size());
      for (renderer::Image& img : references) {
        img.width = v.width;
        img.height = v.height;
        img.rgb.assign(static_cast<size_t>(v.width) * v.height * 3, 0.0f);
      }
      std::vector<double> psnr, ssim;
      imaging::ChartSeries series{v.name + " (" + v.viewSet + ")", {}, true};
      renderer::ReferenceOptions ro;
      ro.width = v.width;
      ro.height = v.height;
      ro.samplesPerPixel = o->referenceSpp;
      for (size_t i : v.referenceViews) {
        references[i] = renderer::renderReference(viewerContext, finalScene, v.views[i].camera, ro);
        const imaging::ImageMetrics m = imaging::compareImages(v.images[i].rgb, references[i].rgb,
                                                           static_cast<int>(v.width), static_cast<int>(v.height));
        psnr.push_back(m.psnrDb);
        ssim.push_back(m.ssim);
        series.points.push_back({static_cast<double>(i), m.psnrDb, fmt::format("view {}", i)});
        progressReferences();
      }
      if (k == 0) {  // how far the reference itself is from converged: two seeds of view 0
        ro.seed = 7;
        const renderer::Image second = renderer::renderReference(viewerContext, finalScene, v.views[0].camera, ro);
        const imaging::ImageMetrics floor =
            imaging::compareImages(second.rgb, references[0].rgb, static_cast<int>(v.width), static_cast<int>(v.height));
        report["reference_noise_floor"] = {{"psnr_db", floor.psnrDb}, {"ssim", floor.ssim}};
        progressReferences();
      }
      const std::string tag = k == 0 ? "stereo" : "quilt";
      writeViewerImages(dir + "/final_" + tag, v, v.images);
      writeViewerImages(dir + "/reference_" + tag, v, references);
      std::string error;
      if (!imaging::writeDifferencePng(dir + "/difference_" + tag + "_view0.png", v.images[0].rgb, references[0].rgb,
                                     static_cast<int>(v.width), static_cast<int>(v.height), 0.25, error))
        throw std::runtime_error(error);
      double meanPsnr = 0, meanSsim = 0;
      for (size_t i = 0; i < psnr.size(); ++i) {
        meanPsnr += psnr[i] / static_cast<double>(psnr.size());
        meanSsim += ssim[i] / static_cast<double>(ssim.size());
      }
      const service::ClientStats st = v.client->stats();
      report["viewers"].push_back({{"name", v.name},
                                   {"views", v.viewSet},
                                   {"view_count", v.views.size()},
                                   {"size", {v.width, v.height}},
                                   {"budget_bytes_per_s", v.budget},
                                   {"frames_applied", st.framesApplied},
                                   {"renders", v.renders},
                                   {"render_ms_per_view_median", median(v.renderMsPerView)},
                                   {"bytes_streaming", streamBytes[k]},
                                   {"bytes_per_s_streaming", static_cast<double>(streamBytes[k]) / streamSeconds},
                                   {"bytes_total", st.bytesReceived},
                                   {"converged_to_server_volume", static_cast<bool>(converged[k])},
                                   {"reference_views", v.referenceViews},
                                   {"psnr_db", psnr},
                                   {"ssim", ssim},
                                   {"psnr_db_mean", meanPsnr},
                                   {"ssim_mean", meanSsim},
                                   {"images",
                                    {{"final", "final_" + tag + ".png"},
                                     {"reference", "reference_" + tag + ".png"},
                                     {"difference_view0", "difference_" + tag + "_view0.png"}}}});
      bandwidthSeries.push_back({v.name, v.bandwidth, true});
      psnrSeries.push_back(std::move(series));
      v.client->stop();
    }
    fmt::print(stderr, "\n");
    server.shutdown();

    phases["references"] = secondsSince(phaseStart);
    report["phase_seconds"] = phases;
    imaging::ChartSpec bw;
    bw.title = "Bytes per second received by each viewer while the light moves";
    bw.xLabel = "seconds";
    bw.yLabel = "bytes/s";
    bw.footnote = commandLine();
    writeTextFile(dir + "/bandwidth.svg", imaging::renderSvgChart(bw, bandwidthSeries));
    imaging::ChartSpec q;
    q.title = "Each view against its reference (light frozen, probes settled)";
    q.xLabel = "view index (quilt order)";
    q.yLabel = "PSNR, dB";
    q.yFromZero = false;
    q.footnote = commandLine();
    writeTextFile(dir + "/psnr_per_view.svg", imaging::renderSvgChart(q, psnrSeries));
    // Speed against accuracy across the pipeline, and the stability suite.
    std::string suites;
    if (!o->skipSuites) {
      suites = runSuites(*o, dir, finalScene, finalT, grid, phases);
      report["phase_seconds"] = phases;
    }
    const double wall = secondsSince(wallStart);
    report["wall_seconds"] = wall;
    writeTextFile(dir + "/report.json", report.dump(2) + "\n");

    std::vector<size_t> above;  // light-field eyes above the scene: they see the ceiling's outer face
    for (size_t i : viewers[1].referenceViews)
      if (viewers[1].views[i].eye.y > finalScene.boundsMax.y) above.push_back(i);
    const std::string md = reportMarkdown(*o, report, serverContext.deviceName(), above) + suites;
    writeTextFile(dir + "/report.md", md);
    for (const auto& v : report["viewers"])
      fmt::print("demo: {:<20} {:>7} {:>4} frames, {:>8.0f} B/s while moving, PSNR {:.2f} dB, SSIM {:.4f}\n",
                 v["name"].get<std::string>(), v["views"].get<std::string>(), v["frames_applied"].get<uint32_t>(),
                 v["bytes_per_s_streaming"].get<double>(), v["psnr_db_mean"].get<double>(),
                 v["ssim_mean"].get<double>());
    fmt::print("demo: wrote {}/report.md (and report.json, charts, images) in {:.0f} s\n", dir, wall);
    exitCode = 0;
  });
}

}  // namespace probecast::app
