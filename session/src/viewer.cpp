#include "probecast/session/viewer.h"

#include <chrono>
#include <cstring>
#include <thread>

#include "probecast/session/scene_loading.h"
#include "probecast/session/scene_state.h"
#include "probecast/session/volumes.h"

namespace probecast::session {

renderer::ViewSetOptions viewSetOptions(const scene::Scene& s, uint32_t width, uint32_t height) {
  const renderer::CameraView camera = renderer::CameraView::fromScene(s);
  renderer::ViewSetOptions vo;
  vo.aspect = static_cast<float>(width) / static_cast<float>(height);
  vo.displayDistance = std::max(0.1f, glm::length(0.5f * (s.boundsMin + s.boundsMax) - camera.position));
  return vo;
}

std::vector<View> priorityViews(const std::vector<renderer::ViewInfo>& views) {
  std::vector<View> out(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    std::memcpy(out[k].viewProj, &views[k].viewProj[0][0], sizeof out[k].viewProj);
    for (int i = 0; i < 3; ++i) out[k].eye[i] = views[k].eye[i];
  }
  return out;
}

Viewer::Viewer(renderer::VulkanContext& context, const scene::Scene& scene, std::vector<renderer::ViewInfo> views,
               ViewerConfig config)
    : config_(std::move(config)), views_(std::move(views)), scene_(scene) {
  client_ = std::make_unique<service::ProbeClient>(config_.client);
  client_->setViews(priorityViews(views_));
  config_.raster.areaLights = {};  // until a stream states its rule: a volume without one holds every emitter
  raster_ = std::make_unique<renderer::RasterRenderer>(context, scene, config_.width, config_.height, config_.raster);
  animates_ = !config_.sceneSpec.empty() && sceneMoves(config_.sceneSpec, scene_);
}

void Viewer::shadeAt(double displayTime) {
  if (animates_) {
    if (posed_ && displayTime == posedAt_) return;  // a still clock: the same pose, the same shadows
    posed_ = true;
    posedAt_ = displayTime;
    advanceScene(config_.sceneSpec, displayTime, scene_);
    raster_->setShading(scene_);
  } else if (!config_.sceneSpec.empty() && held_.hasState && !(held_.state.lights == shadedState_.lights)) {
    scene::Scene lit = scene_;
    applyLights(held_.state, lit);
    raster_->setShading(lit);
    shadedState_ = held_.state;
  }
}

void Viewer::followAreaLights(const AreaLightRule& rule) {
  const scene::AreaLightOptions o = followAreaLightRule(rule, config_.areaLights, std::nullopt, config_.client.address);
  if (rule == lit_) return;
  raster_->setAreaLights(scene_, o);
  lit_ = rule;
}

void Viewer::setViews(std::vector<renderer::ViewInfo> views, bool tellServer) {
  if (views.empty()) throw std::invalid_argument("a viewer needs at least one view");
  views_ = std::move(views);
  if (tellServer) client_->setViews(priorityViews(views_));
}

void Viewer::start() { client_->start(); }
void Viewer::stop() { client_->stop(); }

void Viewer::waitFor(double seconds) const {
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::duration<double>(seconds) && !client_->stats().fatal)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

bool Viewer::renderIfNew() {
  if (client_->stats().framesApplied == stats_.framesSeen) return false;
  return render();
}

bool Viewer::render() {
  // A frame every display refresh: the volume is copied and uploaded only when frames arrived
  // since the last upload; otherwise the one held is drawn again at the new display time.
  const bool fresh = !uploaded_ || client_->stats().framesApplied != held_.framesApplied;
  if (fresh) {
    if (!client_->snapshot(held_)) return false;  // into the storage of the last snapshot
    followAreaLights(held_.volume.areaLights);
  }
  stats_.framesSeen = held_.framesApplied;
  shadeAt(clock_.at(held_, service::wallClockUs()));
  if (fresh) {
    raster_->setProbes(held_.volume);
    uploaded_ = true;
  }
  images_ = raster_->renderViews(views_);
  stats_.renderMsPerView.push_back(raster_->timings().viewsMs / static_cast<double>(views_.size()));
  ++stats_.renders;
  return true;
}

}  // namespace probecast::session
