// `probecast view --connect`: the scene of a server's stream, and its viewers (rendered after
// --wait, or a live window), with what the client refused said once per reason.
#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

#include "view.h"
#include "probecast/session/viewer.h"

namespace probecast::app {
namespace {

// A stream's state for the status line: connection, stalls, bytes per second.
class StreamStatus {
 public:
  explicit StreamStatus(const session::Viewer& viewer) : viewer_(viewer) {}
  std::string line() {
    const service::ClientStats st = viewer_.clientStats();
    const auto now = std::chrono::steady_clock::now();
    if (st.framesApplied != lastFrames_) {
      lastFrames_ = st.framesApplied;
      lastFrameAt_ = now;
    }
    const double window = std::chrono::duration<double>(now - rateFrom_).count();
    if (window >= 1.0) {
      rate_ = static_cast<double>(st.bytesReceived - rateBytes_) / window;
      rateBytes_ = st.bytesReceived;
      rateFrom_ = now;
    }
    std::string state;
    if (st.fatal)
      state = "refused: " + st.lastError;
    else if (!st.connected)
      state = "reconnecting" + (st.lastError.empty() ? std::string() : ": " + st.lastError);
    else if (st.framesApplied == 0)
      state = "connected, waiting for the first volume";
    else if (const double quiet = std::chrono::duration<double>(now - lastFrameAt_).count(); quiet > 2.0)
      state = fmt::format("connected to {}, no new lighting for {:.0f} s", st.address, quiet);
    else
      state = "connected to " + st.address;
    if (st.framesApplied == 0) return state;
    return fmt::format("t {:.2f} s | probes {:.2f} s old | {:.1f} kB/s | {}", viewer_.displayTime(),
                       viewer_.probeAge(), rate_ / 1e3, state);
  }

 private:
  const session::Viewer& viewer_;
  uint32_t lastFrames_ = 0;
  std::chrono::steady_clock::time_point lastFrameAt_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point rateFrom_ = std::chrono::steady_clock::now();
  uint64_t rateBytes_ = 0;
  double rate_ = 0.0;
};

// What the client refused from the server, once per reason (wire text escaped).
void printRefusals(const service::ClientStats& st) {
  for (const std::string& line : service::refusalLines(st)) fmt::print("view: refused: {}\n", line);
}

// A viewer of the stream --connect names, drawing `sceneSpec` at its display clock.
session::ViewerConfig streamViewerConfig(const ViewOptions& o, const std::string& sceneSpec,
                                         const renderer::RasterOptions& ro) {
  session::ViewerConfig vc;
  vc.width = o.size[0];
  vc.height = o.size[1];
  vc.raster = ro;
  vc.client = o.connection.client("probecast-view");
  vc.client.zh3PerPixel = true;
  vc.client.scene = o.streamScene;
  if (o.repr != "float") vc.client.representation = session::parseRepresentationOrThrow(o.repr);  // transcoded
  if (o.areaLights.mode != "auto") vc.areaLights = o.areaLights.mode == "on";
  vc.sceneSpec = sceneSpec;  // direct light at the display clock, locked to the stream's
  return vc;
}

}  // namespace

// The scene a --connect viewer draws: the stream's (fetched, or its own --scene checked against it).
session::ViewerScene streamScene(const ViewOptions& o) {
  const service::ClientConfig cc = o.connection.client("probecast-view");
  SceneStamp stamp;
  std::string error;
  orThrow(service::describeScene(cc, stamp, error), error);
  session::SceneChoice choice;
  if (o.tracing.scene.sceneGiven()) choice.localSpec = o.tracing.scene.scene;
  if (o.tracing.scene.environment.given()) choice.localLighting = o.tracing.scene.environment.request();
  choice.cache = o.sceneCache.empty() ? service::defaultSceneCache() : std::filesystem::path(o.sceneCache);
  choice.maxBytes = o.sceneMaxBytes;
  service::SceneFetch fetch;
  session::ViewerScene vs = session::resolveViewerScene(stamp, choice, cc, fetch);
  vs.time = stamp.time;
  fmt::print("view: {}\n", vs.note);
  return vs;
}

// A viewer of a server's stream: subscribe for --wait seconds, then render what it holds at its
// display clock (`sceneSpec` shaded at the display time).
Rendered renderFromServer(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                          const std::string& sceneSpec, const std::vector<renderer::ViewInfo>& views,
                          const renderer::RasterOptions& ro) {
  session::Viewer viewer(context, s, views, streamViewerConfig(o, sceneSpec, ro));
  viewer.start();
  viewer.waitFor(o.waitSeconds);
  viewer.stop();
  const service::ClientStats st = viewer.clientStats();
  // A refused subscription (bad token, too many views) may have delivered part of a volume:
  // rendering it would pass a wrong picture off as the server's.
  printRefusals(st);
  if (st.fatal) throw std::runtime_error("the server refused the subscription: " + st.lastError);
  service::VolumeSnapshot held;
  // A description without a frame applied is a volume of zeros: drawing it would pass darkness off
  // as the server's light.
  if (!viewer.snapshot(held) || st.framesApplied == 0)
    throw std::runtime_error("no probe lighting from " + o.connection.connect + " in " +
                             fmt::format("{:g}", o.waitSeconds) + " s" +
                             (st.lastError.empty() ? std::string() : ": " + st.lastError));
  fmt::print("view: {} frames ({} bytes) from {}\n", st.framesApplied, st.bytesReceived, o.connection.connect);
  o.areaLights.follow(held.volume.areaLights, o.connection.connect);  // refused before anything is drawn
  viewer.render();
  printAreaLights(viewer.areaLightRule(), viewer.areaLights());
  fmt::print("view: drawn at scene time {:.4f} (display clock); probes traced at {:.4f}, {:.4f} s older; clock offset "
             "{:.1f} ms\n",
             viewer.displayTime(), held.volume.scene.time, viewer.probeAge(),
             static_cast<double>(viewer.clockOffsetUs()) / 1e3);
  return {viewer.images(), viewer.timings().viewsMs, viewer.timings().shadowMs};
}

// A live window on a server's stream: every display frame drawn at the display clock from the
// newest volume held, through stalls and reconnects.
void windowFromServer(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                      const std::string& sceneSpec, const renderer::ViewSetSpec& spec,
                      const renderer::ViewSetOptions& vso, const renderer::RasterOptions& ro,
                      const renderer::LookingGlassCalibration* lg) {
  const renderer::CameraView start = renderer::CameraView::fromScene(s);
  session::Viewer viewer(context, s, renderer::makeViewSet(start, spec, vso), streamViewerConfig(o, sceneSpec, ro));
  viewer.start();
  StreamStatus status(viewer);
  FrameSource source;
  auto lastTold = std::chrono::steady_clock::now();
  bool untold = false;  // the server's priority has not seen the camera's latest views
  source.render = [&](const std::vector<renderer::ViewInfo>& views, bool moved, std::vector<renderer::Image>& images) {
    // The server ranks bricks by these views: told at most 4 times a second while the camera moves.
    untold = untold || moved;
    const bool tell = untold && std::chrono::steady_clock::now() - lastTold > std::chrono::milliseconds(250);
    if (moved || tell) viewer.setViews(views, tell);
    if (tell) {
      lastTold = std::chrono::steady_clock::now();
      untold = false;
    }
    if (!viewer.render()) return false;
    images = viewer.images();
    return true;
  };
  source.status = [&] { return status.line(); };
  source.setRenderScale = [&](float scale) { viewer.setRenderScale(scale); };
  showOnLookingGlass(source, context, lg);
  runLiveWindow(o.window, context, start, spec, vso, o.size[0], o.size[1],
                glm::length(s.boundsMax - s.boundsMin), source, o.out, o.exposure, toneMapOf(o));
  viewer.stop();
  const service::ClientStats st = viewer.clientStats();
  printRefusals(st);
  if (st.fatal) throw std::runtime_error("the server refused the subscription: " + st.lastError);
}

}  // namespace probecast::app
