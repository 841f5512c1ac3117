// The producer side of a session: a lighting source (a scene traced by the probe updater, a
// baked volume, or generated frames) published to a ProbeHub, optionally served over gRPC, in a
// paced loop on the caller's thread or a thread of its own, with the animation parameter t
// driven by wall time or by steps.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"
#include "probecast/service/bus_nats.h"
#include "probecast/service/probe_hub.h"
#include "probecast/service/server.h"

namespace probecast::session {

// How the loop spaces its steps.
struct Pacing {
  enum class Mode {
    Free,        // one step after another
    FixedRate,   // `hz` steps per second; a late step starts at once
    FixedSleep,  // a pause of `sleepMs` after every step
  };
  Mode mode = Mode::Free;
  double hz = 10.0;
  double sleepMs = 0.0;
  double seconds = 0.0;  // the loop ends after this long (0 = when stopped or interrupted)
};

// The scene clock of a traced scene, seconds (built-in scenes move their light once around per
// scene second: their animation parameter t is the scene time mod 1).
struct Animation {
  enum class Mode {
    Still,      // the scene time stays at `start`
    WallClock,  // scene time = start + ratePerSecond × seconds since the loop started (frames say the rate)
    PerStep,    // the scene time advances by `perStep` before every update (frames say rate 0: steps)
  };
  Mode mode = Mode::Still;
  float start = 0.0f;
  double ratePerSecond = 0.0;
  float perStep = 0.0f;
  bool reloadScene = true;  // load the scene at t before every update (false: t is only reported)
};

struct ProducerStats {
  uint32_t updates = 0;         // steps that published new lighting
  uint32_t settledUpdates = 0;  // of those, the ones that began with the animation frozen
  std::vector<double> updateMs; // the updater's own time per update, ms (traced scenes; the newest 2¹⁶ at most)
  double publishMs = 0.0;       // time spent in ProbeHub::publish (encoding), all steps, ms
};

// Set the source (traceScene, serveVolume or generate) before start(); step() and the setters of
// the source are not for use while the producer's own thread runs.
class ProbeProducer {
 public:
  static constexpr size_t kMaxUpdateSamples = size_t{1} << 16;
  using Clock = std::chrono::steady_clock;
  // Fills `probes` (27 floats per probe, all active) with lighting frame number `frame`.
  using FrameGenerator = std::function<void(uint32_t frame, std::vector<float>& probes)>;

  explicit ProbeProducer(const service::HubConfig& hub);
  ~ProbeProducer();  // stops the loop and the server
  ProbeProducer(const ProbeProducer&) = delete;
  ProbeProducer& operator=(const ProbeProducer&) = delete;

  // Serves the hub over gRPC; returns the port. Throws like ProbeServer.
  int serve(const service::ServerConfig& config);
  int port() const;
  void shutdownServer();
  service::ProbeServer* server() { return server_.get(); }  // null until serve()
  // Publishes every brick version to the probe bus as well (edges serve from it). Throws like BusPublisher.
  void publishTo(const service::BusConfig& bus);
  // The bus publisher's counters (all zero when not publishing).
  service::PublisherStats busStats() const;

  // The lighting source (one of three). A traced scene: `first` is `sceneSpec` at the animation's start.
  // With a ray budget (options.raysPerUpdate), every update first tells the updater which probes
  // the hub's subscribers can see (probe_interest.h).
  void traceScene(renderer::VulkanContext& context, const std::string& sceneSpec, const scene::Scene& first,
                  const ProbeGrid& grid, const renderer::UpdaterOptions& options, const Animation& animation);
  // A fixed volume (its area light rule with it): published once now; every step then only ticks the hub's budgets.
  void serveVolume(const ProbeVolume& volume);
  // Generated frames 0, 1, 2, … one per step while moving (setMoving), ticks otherwise.
  void generate(FrameGenerator generator);

  // One step of the source: animate, update, publish (or tick).
  void step();
  // Steps paced until stopped, `interrupted`, or pacing.seconds; `afterStep` gets the seconds since the start.
  void run(const Pacing& pacing, const std::atomic<bool>* interrupted = nullptr,
           const std::function<void(double seconds)>& afterStep = {});
  // The same loop on a thread of its own; an exception ends it, passed to `onError` and kept in error().
  void start(const Pacing& pacing, std::function<void(const std::string&)> onError = {});
  // Ends the loop (and joins its thread).
  void stop();
  bool running() const { return running_; }
  std::string error() const;

  // The animation holds its current t (or `at`) from now on; updates that begin afterwards count
  // as settled.
  void freeze();
  void freeze(float at);
  // Generated frames: false holds the lighting (steps only tick), true moves on.
  void setMoving(bool moving) { moving_ = moving; }
  // Any producer: true publishes nothing more (steps only tick the hub, tracing stops), so every
  // subscriber settles on the last lighting published; false goes on.
  void hold(bool held) { held_ = held; }
  // The scene time now (wall-clock animation: at this moment; otherwise of the last update), and
  // the built-in scenes' animation parameter t of it.
  double sceneTime() const;
  float t() const;
  // When the loop (start or run) began.
  Clock::time_point started() const { return started_; }

  ProducerStats stats() const;
  service::ProbeHub& hub() { return hub_; }
  const service::ProbeHub& hub() const { return hub_; }

 private:
  void loop(const Pacing& pacing, const std::atomic<bool>* interrupted, const std::function<void(double)>& afterStep);

  service::ProbeHub hub_;
  std::unique_ptr<service::ProbeServer> server_;
  std::unique_ptr<service::BusPublisher> publisher_;  // before hub_ in destruction: it detaches from it
  // Source.
  std::unique_ptr<renderer::ProbeUpdater> updater_;
  std::string sceneSpec_;
  std::atomic<bool> held_{false};
  bool rayBudget_ = false;  // the updater spends a ray budget: it is told the subscribers' views
  bool noiseRule_ = false;  // the hub's encoder holds noise (EncoderOptions::noiseScale): and so is it
  // told how much each probe changes the subscribers' views (probeViewSensitivity): the surfaces
  // the views show are found again when the views or the geometry change, weighed by the volume's
  // light at every update, and blended into the weights slowly (blendViewWeights).
  std::vector<float> viewFootprints(const std::vector<View>& views);
  scene::Scene current_;   // the scene at the last update's time (posed or made again per update)
  scene::Scene geometry_;  // the triangles traced (positions, indices, materials of the last scene set)
  scene::AreaLightOptions areaLights_;      // the updater's: what viewers light themselves
  renderer::SurfaceLighting lighting_;      // of the last scene set
  std::vector<scene::Material> lightingMaterials_;  // the materials lighting_ is of
  std::vector<View> footprintViews_;        // the views viewSurfaces_ are of
  std::vector<renderer::ViewSample> viewSurfaces_;
  bool footprintsStale_ = true;
  std::vector<glm::vec3> direct_;           // sampleDirectLight of viewSurfaces_ under directLights_
  std::vector<scene::Light> directLights_;
  bool directStale_ = true;
  std::vector<float> viewWeights_;          // what the hub is given: the sensitivities, blended over updates
  Animation animation_;
  FrameGenerator generator_;
  std::vector<float> frame_;
  uint32_t frameIndex_ = 0;
  // Loop.
  std::thread thread_;
  std::atomic<bool> stop_{false}, running_{false}, moving_{true}, frozen_{false};
  std::atomic<float> t_{0.0f}, frozenT_{0.0f};
  std::atomic<double> sceneTime_{0.0};
  std::vector<bus::LightState> lights_;  // of the scene at the last update
  Clock::time_point started_ = Clock::now();
  mutable std::mutex mutex_;
  ProducerStats stats_;
  std::string error_;
};

}  // namespace probecast::session
