#include "probecast/session/probe_producer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "probecast/renderer/probe_interest.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/scene_state.h"
#include "probecast/session/volumes.h"

namespace probecast::session {

ProbeProducer::ProbeProducer(const service::HubConfig& hub) : hub_(hub), noiseRule_(hub.encoder.noiseScale > 0.0f) {}

ProbeProducer::~ProbeProducer() {
  stop();
  shutdownServer();
  publisher_.reset();
}

int ProbeProducer::serve(const service::ServerConfig& config) {
  server_ = std::make_unique<service::ProbeServer>(config, hub_);
  return server_->port();
}

int ProbeProducer::port() const { return server_ ? server_->port() : 0; }

void ProbeProducer::publishTo(const service::BusConfig& bus) {
  publisher_ = std::make_unique<service::BusPublisher>(bus, hub_);
}

service::PublisherStats ProbeProducer::busStats() const {
  return publisher_ ? publisher_->stats() : service::PublisherStats{};
}

void ProbeProducer::shutdownServer() {
  if (server_) server_->shutdown();
}

void ProbeProducer::traceScene(renderer::VulkanContext& context, const std::string& sceneSpec,
                               const scene::Scene& first, const ProbeGrid& grid,
                               const renderer::UpdaterOptions& options, const Animation& animation) {
  updater_ = std::make_unique<renderer::ProbeUpdater>(context, first, grid, options);
  hub_.setProbeOffsets(updater_->volume().offsets);  // in the description before anyone subscribes
  hub_.setAreaLightRule(areaLightRuleOf(options.areaLights));  // what the probes leave out for viewers
  sceneSpec_ = sceneSpec;
  current_ = first;
  geometry_.positions = first.positions;
  geometry_.indices = first.indices;
  geometry_.triangleMaterial = first.triangleMaterial;
  areaLights_ = options.areaLights;
  viewWeights_.clear();
  // for the view weights only
  lighting_ = noiseRule_ ? renderer::surfaceLighting(first, areaLights_) : renderer::SurfaceLighting{};
  lightingMaterials_ = first.materials;
  footprintsStale_ = true;
  rayBudget_ = options.raysPerUpdate > 0;
  animation_ = animation;
  t_ = animation.start;
  sceneTime_ = animation.start;
  lights_ = lightStates(first);
}

void ProbeProducer::serveVolume(const ProbeVolume& volume) {
  hub_.setAreaLightRule(volume.areaLights);
  hub_.publish(volume);
}

void ProbeProducer::generate(FrameGenerator generator) { generator_ = std::move(generator); }

float ProbeProducer::t() const { return animationT(sceneTime()); }

double ProbeProducer::sceneTime() const {
  if (frozen_) return frozenT_;
  if (animation_.mode != Animation::Mode::WallClock || !running_) return sceneTime_;
  const double seconds = std::chrono::duration<double>(Clock::now() - started_).count();
  return animation_.start + animation_.ratePerSecond * seconds;
}

void ProbeProducer::freeze() { freeze(static_cast<float>(sceneTime())); }

void ProbeProducer::freeze(float at) {
  frozenT_ = at;
  frozen_ = true;
}

void ProbeProducer::step() {
  if (held_) {
    hub_.tick();
  } else if (updater_) {
    const bool wasFrozen = frozen_;
    const uint64_t clockUs = service::wallClockUs();
    if (!wasFrozen && animation_.mode == Animation::Mode::PerStep) sceneTime_ = sceneTime_ + animation_.perStep;
    if (!wasFrozen && animation_.mode == Animation::Mode::WallClock) sceneTime_ = sceneTime();  // what it says once the loop ends
    if (wasFrozen) sceneTime_ = frozenT_.load();
    const double time = sceneTime_;
    t_ = animationT(time);
    const bool playing = !wasFrozen && animation_.mode == Animation::Mode::WallClock;
    if (animation_.mode != Animation::Mode::Still && animation_.reloadScene) {
      advanceScene(sceneSpec_, time, current_);
      const scene::Scene& next = current_;
      lights_ = lightStates(next);
      updater_->setScene(next);
      if (next.positions != geometry_.positions || next.indices != geometry_.indices ||
          next.triangleMaterial != geometry_.triangleMaterial) {
        geometry_.positions = next.positions;
        geometry_.indices = next.indices;
        geometry_.triangleMaterial = next.triangleMaterial;
        footprintsStale_ = true;
      }
      if (noiseRule_ && next.materials != lightingMaterials_) {
        lighting_ = renderer::surfaceLighting(next, areaLights_);
        lightingMaterials_ = next.materials;
        directStale_ = true;
      } else if (noiseRule_) {
        lighting_.lights = next.lights;
      }
    }
    // The ray budget traces first what the subscribers can see now; the noise rule holds what none
    // of them sees longer.
    if (rayBudget_ || noiseRule_) {
      const std::vector<View> views = hub_.subscriberViews();
      if (noiseRule_) hub_.setViewWeights(viewFootprints(views));
      if (rayBudget_)
        updater_->setViewWeights(renderer::probeViewWeights(updater_->grid(), updater_->volume().offsets, views));
    }
    const renderer::UpdateStats st = updater_->update();
    hub_.setSceneState({time, playing ? animation_.ratePerSecond : 0.0, clockUs, lights_});
    const auto t0 = Clock::now();
    hub_.publish(updater_->volume());
    const double publishMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.updates;
    if (wasFrozen) ++stats_.settledUpdates;
    if (stats_.updateMs.size() >= kMaxUpdateSamples)  // a serve that runs for days: keep the newest
      stats_.updateMs.erase(stats_.updateMs.begin(), stats_.updateMs.begin() + kMaxUpdateSamples / 2);
    stats_.updateMs.push_back(st.milliseconds);
    stats_.publishMs += publishMs;
  } else if (generator_ && moving_) {
    generator_(frameIndex_++, frame_);
    const auto t0 = Clock::now();
    hub_.publish(frame_.data(), nullptr);
    const double publishMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.updates;
    stats_.publishMs += publishMs;
  } else {
    hub_.tick();
  }
}

std::vector<float> ProbeProducer::viewFootprints(const std::vector<View>& views) {
  const auto same = [](const std::vector<View>& a, const std::vector<View>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(View)) == 0);
  };
  if (views.empty()) {
    viewWeights_.clear();
    return {};
  }
  if (footprintsStale_ || !same(views, footprintViews_)) {
    const std::vector<View> sampled = renderer::spreadViews(views, renderer::kFootprintViews);
    const glm::uvec2 size = renderer::footprintSampleSize(sampled.size());
    viewSurfaces_ = renderer::sampleViewSurfaces(geometry_, updater_->grid(), updater_->volume().active,
                                       updater_->volume().offsets, sampled, size.x, size.y);
    footprintViews_ = views;
    footprintsStale_ = false;
    directStale_ = true;
  }
  if (directStale_ || direct_.size() != viewSurfaces_.size() || lighting_.lights != directLights_) {
    direct_ = renderer::sampleDirectLight(geometry_, viewSurfaces_, lighting_);
    directLights_ = lighting_.lights;
    directStale_ = false;
  }
  // The probes' light changes every update: weigh the surfaces by what the volume holds now, and
  // blend that into the weights slowly (blendViewWeights: one noisy update must not move them).
  renderer::blendViewWeights(viewWeights_, renderer::probeViewSensitivity(viewSurfaces_, direct_, lighting_,
                                                                          updater_->volume().probes,
                                                                          updater_->grid().count()));
  return viewWeights_;
}

void ProbeProducer::loop(const Pacing& pacing, const std::atomic<bool>* interrupted,
                         const std::function<void(double)>& afterStep) {
  const auto start = started_;
  auto next = start;
  const auto period = pacing.mode == Pacing::Mode::FixedRate
                          ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / pacing.hz))
                          : Clock::duration::zero();
  while (!stop_ && !(interrupted && *interrupted)) {
    const auto now = Clock::now();
    if (pacing.seconds > 0 && now - start >= std::chrono::duration<double>(pacing.seconds)) break;
    step();
    if (afterStep) afterStep(std::chrono::duration<double>(now - start).count());
    if (pacing.mode == Pacing::Mode::FixedRate) {
      next += period;
      std::this_thread::sleep_until(next);
    } else if (pacing.mode == Pacing::Mode::FixedSleep) {
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(pacing.sleepMs));
    }
  }
}

void ProbeProducer::run(const Pacing& pacing, const std::atomic<bool>* interrupted,
                        const std::function<void(double)>& afterStep) {
  started_ = Clock::now();
  stop_ = false;
  running_ = true;
  try {
    loop(pacing, interrupted, afterStep);
  } catch (...) {
    running_ = false;
    throw;
  }
  running_ = false;
}

void ProbeProducer::start(const Pacing& pacing, std::function<void(const std::string&)> onError) {
  stop();
  started_ = Clock::now();
  stop_ = false;
  running_ = true;
  thread_ = std::thread([this, pacing, onError = std::move(onError)] {
    try {
      loop(pacing, nullptr, {});
    } catch (const std::exception& e) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = e.what();
      }
      if (onError) onError(e.what());
    }
    running_ = false;
  });
}

void ProbeProducer::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::string ProbeProducer::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

ProducerStats ProbeProducer::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace probecast::session
