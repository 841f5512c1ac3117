// `probecast demo`, the session: the server (its own Vulkan device, the updater, the hub, gRPC on
// a free loopback port) lights the scene while its light moves; a stereo headset and a
// light-field display (a second Vulkan device) subscribe and re-render as lighting arrives.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

#include "commands.h"
#include "demo.h"
#include "progress.h"
#include "probecast/imaging/image_io.h"
#include "probecast/session/scene_state.h"
#include "probecast/session/representation.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/volumes.h"
#include "scene_options.h"

namespace probecast::app {

double secondsSince(DemoClock::time_point t0) {
  return std::chrono::duration<double>(DemoClock::now() - t0).count();
}

void writeViewerImages(const std::string& prefix, const DemoViewer& v, const std::vector<renderer::Image>& images) {
  const renderer::Image quilt = renderer::composeQuilt(images, v.viewer->views(), v.spec.columns, v.spec.rows);
  std::string error;
  if (!imaging::writePngPreview(prefix + ".png", quilt.rgb, static_cast<int>(quilt.width),
                              static_cast<int>(quilt.height), 1.0f, error))
    throw std::runtime_error(error);
}

namespace {

// The server: the updater tracing the scene as its t follows wall time, the hub, gRPC on loopback.
service::ServerConfig startServer(const DemoOptions& o, DemoRun& run) {
  run.scene0 = session::loadSceneOrThrow(o.scene, 0.0f);
  run.grid = o.grid.resolve(run.scene0);
  run.serverContext = std::make_unique<renderer::VulkanContext>(o.device.context());
  service::HubConfig hub = service::hubConfigFor(run.grid, session::parseRepresentationOrThrow(o.repr), 4, 1);
  hub.encoder.noiseScale = o.encoder.noiseScale;
  hub.encoder.refinementInterval = o.encoder.refinementInterval;
  service::ScenePackage package;  // the scene and sky the descriptions name, as serve's do
  std::string error;
  if (!service::makeScenePackage(o.scene, o.environment.request(), package, error)) throw std::runtime_error(error);
  hub.scene = session::stampOf(package, 0.0);
  run.producer = std::make_unique<session::ProbeProducer>(hub);
  renderer::UpdaterOptions uo;
  uo.samplesPerProbe = o.spp;
  uo.environment = o.sky;
  uo.areaLights = o.areaLights.options();  // stated in the description: the viewers light the same emitters
  session::Animation animation;
  animation.mode = session::Animation::Mode::WallClock;
  animation.ratePerSecond = o.rate;
  animation.reloadScene = session::sceneMoves(o.scene, run.scene0);  // built-ins and animated glTF files
  run.producer->traceScene(*run.serverContext, o.scene, run.scene0, run.grid, uo, animation);
  service::ServerConfig sc;
  sc.plaintext = true;  // loopback only
  std::random_device rd;
  sc.token = fmt::format("demo-{:08x}{:08x}", rd(), rd());
  sc.scene = std::make_shared<const service::ScenePackage>(std::move(package));
  const int port = run.producer->serve(sc);
  sc.listen = fmt::format("127.0.0.1:{}", port);
  fmt::print(
      "demo: server on 127.0.0.1:{} lighting {} ({}x{}x{} probes, {} spp/update, {}, client area lights {}), light "
      "moving for {:.0f} s\n",
      port, run.scene0.name, run.grid.dims[0], run.grid.dims[1], run.grid.dims[2], o.spp, o.repr, o.areaLights.mode,
      o.seconds);
  return sc;
}

// The viewers on a Vulkan device of their own (a headset and a display are other machines).
void startViewers(const DemoOptions& o, const service::ServerConfig& server, DemoRun& run) {
  run.viewerContext = std::make_unique<renderer::VulkanContext>(o.device.context(/*rayTracing=*/false));
  run.viewers.resize(2);
  run.viewers[0].name = "headset";
  run.viewers[0].viewSet = "stereo";
  run.viewers[0].width = 192;
  run.viewers[0].height = 120;
  run.viewers[1].name = "light-field display";
  run.viewers[1].viewSet = o.lightField;
  run.viewers[1].width = 128;
  run.viewers[1].height = 80;
  run.viewers[1].budget = o.lightFieldBudget;
  for (DemoViewer& v : run.viewers) {
    std::string error;
    orThrow(renderer::parseViewSet(v.viewSet, v.spec, error), error);
    session::ViewerConfig vc;
    vc.width = v.width;
    vc.height = v.height;
    vc.raster.visibility = o.visibility;
    vc.raster.samplesPerSide = o.supersample;
    vc.raster.msaaSamples = o.msaa;
    vc.raster.anisotropy = o.anisotropy;
    vc.client.address = server.listen;
    vc.client.token = server.token;
    vc.client.name = v.name;
    vc.client.budgetBytesPerSecond = v.budget;
    vc.client.zh3PerPixel = true;
    vc.raster.environment = o.sky;  // the background; its light comes through the probes
    vc.sceneSpec = o.scene;  // direct light is local, at the display clock locked to the stream's
    v.viewer = std::make_unique<session::Viewer>(
        *run.viewerContext, run.scene0,
        renderer::makeViewSet(renderer::CameraView::fromScene(run.scene0), v.spec,
                              session::viewSetOptions(run.scene0, v.width, v.height)),
        vc);
    v.viewer->start();
  }
}

// Streaming with the light moving: re-render as lighting arrives, images at three moments.
void stream(const DemoOptions& o, DemoRun& run) {
  Progress progress("demo");
  session::ProbeProducer& producer = *run.producer;
  const double moment[3] = {o.seconds / 3.0, 2.0 * o.seconds / 3.0, o.seconds};
  int nextMoment = 0;
  double lastSample = 0.0;
  while (producer.running()) {
    const double now = secondsSince(producer.started());
    bool rendered = false;
    for (DemoViewer& v : run.viewers) rendered |= v.viewer->renderIfNew();
    if (now - lastSample >= 1.0) {
      for (DemoViewer& v : run.viewers) {
        const uint64_t bytes = v.viewer->clientStats().bytesReceived;
        v.bandwidth.push_back({now, static_cast<double>(bytes - v.lastBytes) / (now - lastSample), ""});
        v.lastBytes = bytes;
      }
      lastSample = now;
    }
    if (nextMoment < 3 && now >= moment[nextMoment]) {
      // Each viewer's images are of its own display time: the scene it drew was posed (or lit) then.
      nlohmann::json m{{"seconds", now}, {"scene_time", producer.sceneTime()}};
      for (size_t k = 0; k < run.viewers.size(); ++k)
        if (!run.viewers[k].viewer->images().empty()) {
          const std::string tag = k == 0 ? "stereo" : "quilt";
          const std::string file = fmt::format("moment{}_{}", nextMoment + 1, tag);
          writeViewerImages(o.out + "/" + file, run.viewers[k], run.viewers[k].viewer->images());
          m[tag] = file + ".png";
          m[tag + "_scene_time"] = run.viewers[k].viewer->displayTime();
        }
      run.moments.push_back(m);
      ++nextMoment;
    }
    const session::ViewerStats &head = run.viewers[0].viewer->stats(), &display = run.viewers[1].viewer->stats();
    progress.update(now / o.seconds,
                    fmt::format("{:4.1f}/{:.0f} s  updates {:4}  headset {:4} frames {:4} renders  display {:4} frames "
                                "{:4} renders",
                                std::min(now, o.seconds), o.seconds, producer.stats().updates, head.framesSeen,
                                head.renders, display.framesSeen, display.renders));
    if (now >= o.seconds) break;
    if (!rendered) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  progress.finish();
  run.streamSeconds = secondsSince(producer.started());
  for (DemoViewer& v : run.viewers) v.streamBytes = v.viewer->clientStats().bytesReceived;
}

// Freeze the light and let the probes settle for o.settleUpdates updates.
void settle(const DemoOptions& o, DemoRun& run) {
  Progress progress("demo");
  session::ProbeProducer& producer = *run.producer;
  // Where the light stands after exactly o.seconds, whatever the loop's timing: the same final
  // scene every run, so its references come from the cache.
  producer.freeze(static_cast<float>(o.seconds * o.rate));
  run.finalT = static_cast<float>(producer.sceneTime());
  while (producer.running() && producer.stats().settledUpdates < o.settleUpdates) {
    const uint32_t settled = producer.stats().settledUpdates;
    progress.update(static_cast<double>(settled) / o.settleUpdates,
                    fmt::format("scene clock frozen at {:.3f} s, settling {}/{} updates", run.finalT, settled,
                                o.settleUpdates));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  producer.stop();
  progress.finish();
}

// Wait (up to 30 s) until both viewers hold the server's volume bit for bit.
void converge(DemoRun& run) {
  const ProbeVolume server = run.producer->hub().reconstruction();
  const auto waitStart = DemoClock::now();
  const auto all = [&] {
    return std::all_of(run.viewers.begin(), run.viewers.end(), [](const DemoViewer& v) { return v.converged; });
  };
  while (secondsSince(waitStart) < 30.0 && !all()) {
    for (DemoViewer& v : run.viewers) {
      service::VolumeSnapshot snap;
      if (!v.viewer->snapshot(snap)) continue;
      v.converged = session::holdsVolume(snap.volume, server);
      if (!v.converged) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

}  // namespace

void runDemoSession(const DemoOptions& o, DemoRun& run) {
  const service::ServerConfig server = startServer(o, run);
  run.producer->start(session::Pacing{},
                      [](const std::string& e) { fmt::print(stderr, "demo: updater stopped: {}\n", e); });
  startViewers(o, server, run);
  run.phases["setup"] = std::chrono::duration<double>(run.producer->started() - run.wallStart).count();
  stream(o, run);
  run.phases["streaming"] = run.streamSeconds;
  auto phaseStart = DemoClock::now();
  settle(o, run);
  run.phases["settling"] = secondsSince(phaseStart);
  phaseStart = DemoClock::now();
  converge(run);
  run.phases["converging"] = secondsSince(phaseStart);
}

}  // namespace probecast::app
