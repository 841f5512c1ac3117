// The viewer side of a session: a ProbeClient subscribed with its views, and a RasterRenderer
// that re-renders them whenever new lighting has arrived.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/scene/scene.h"
#include "probecast/service/client.h"

namespace probecast::session {

// View sets of width × height with the display plane through the centre of the scene's bounds.
renderer::ViewSetOptions viewSetOptions(const scene::Scene& scene, uint32_t width, uint32_t height);
// The same views as the service's frustum priority takes them.
std::vector<View> priorityViews(const std::vector<renderer::ViewInfo>& views);

struct ViewerConfig {
  uint32_t width = 0, height = 0;  // of each view
  service::ClientConfig client;
  renderer::RasterOptions raster;  // its areaLights give way to the stream's rule (below)
  // Client area lights follow the rule the stream's probes were made with (its volume
  // description): on exactly when the producer left emitters out, with its threshold, so light is
  // neither counted twice nor lost. Set, the viewer asks for area lights on (true) or off (false)
  // and render() throws std::runtime_error, rendering nothing, when the stream says otherwise.
  std::optional<bool> areaLights;
  // Direct light is local, at the viewer's display clock (service::DisplayClock, locked to the
  // stream's scene clock): when set, a scene that moves (sceneMoves) is posed or made as `sceneSpec`
  // at the display time before every render; one that does not takes the lights of the newest
  // frame's scene state.
  std::string sceneSpec;
};

struct ViewerStats {
  uint32_t framesSeen = 0;              // frames applied when it last rendered
  uint32_t renders = 0;
  std::vector<double> renderMsPerView;  // per render
};

class Viewer {
 public:
  Viewer(renderer::VulkanContext& context, const scene::Scene& scene, std::vector<renderer::ViewInfo> views,
         ViewerConfig config);

  // Subscribes (sending the views for the server's priority) / unsubscribes, keeping what it holds.
  void start();
  void stop();
  // Waits until `seconds` have passed or the server refused the subscription.
  void waitFor(double seconds) const;

  // Renders when frames arrived since the last render; false otherwise.
  bool renderIfNew();
  // Renders what it holds now at the display clock (a live window calls it every frame: the
  // volume is uploaded again only when frames arrived); false while it holds nothing.
  bool render();
  // Other views from now on (a camera that moved); `tellServer`: also for the server's priority.
  void setViews(std::vector<renderer::ViewInfo> views, bool tellServer = true);
  void setShading(const scene::Scene& scene) { raster_->setShading(scene); }

  const std::vector<renderer::Image>& images() const { return images_; }
  const std::vector<renderer::ViewInfo>& views() const { return views_; }
  const ViewerStats& stats() const { return stats_; }
  service::ClientStats clientStats() const { return client_->stats(); }
  bool snapshot(service::VolumeSnapshot& out) const { return client_->snapshot(out); }
  const renderer::RasterTimings& timings() const { return raster_->timings(); }
  // Draws the next frames at this scale of the views' size (RasterRenderer::setRenderScale).
  void setRenderScale(float scale) { raster_->setRenderScale(scale); }
  // The rule the viewer lights by now (that of the last volume rendered).
  const AreaLightRule& areaLightRule() const { return lit_; }
  const scene::AreaLightSet& areaLights() const { return raster_->areaLights(); }
  // The scene time the last render drew at, the probes' age then (scene seconds), and the clock
  // offset it was locked with (the server's clock is ours minus this).
  double displayTime() const { return clock_.last(); }
  double probeAge() const { return clock_.probeAge(); }
  int64_t clockOffsetUs() const { return held_.clockOffsetUs; }

 private:
  ViewerConfig config_;
  std::vector<renderer::ViewInfo> views_;
  std::unique_ptr<service::ProbeClient> client_;
  // Lights by `rule` from now on (or throws, see ViewerConfig::areaLights).
  void followAreaLights(const AreaLightRule& rule);

  scene::Scene scene_;  // for planning area lights when a stream's rule arrives
  std::unique_ptr<renderer::RasterRenderer> raster_;
  AreaLightRule lit_;
  service::VolumeSnapshot held_;  // what it rendered last; its storage is reused
  bool uploaded_ = false;         // held_ is in the raster renderer
  service::DisplayClock clock_;
  bool animates_ = false;         // sceneSpec moves with the scene time
  bool posed_ = false;            // scene_ is posed at posedAt_ (animates_)
  double posedAt_ = 0.0;
  bus::SceneState shadedState_;  // the state whose lights it shades with (scenes that do not animate)
  // Shades direct light for the display time (see ViewerConfig::sceneSpec).
  void shadeAt(double displayTime);
  std::vector<renderer::Image> images_;
  ViewerStats stats_;
};

}  // namespace probecast::session
