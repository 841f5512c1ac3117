// Client area lights through a real server over loopback: a viewer lights the emitters itself
// exactly when the stream's probes say they were left out, with the producer's threshold, and a
// viewer that asks for the opposite is refused rather than counting light twice or losing it.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "probecast/renderer/view_sets.h"
#include "probecast/scene/scene.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/viewer.h"
#include "probecast/session/volumes.h"
#include "vulkan_test_support.h"

namespace probecast {
namespace {

using namespace std::chrono_literals;

scene::Scene cornell() {
  scene::Scene s;
  std::string error;
  if (!scene::loadScene(std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-box/CornellBox-Original.gltf", 0, s, error))
    throw std::runtime_error(error);
  return s;
}

// Renders once the viewer holds a volume (10 s at most).
bool renderWhenHeld(session::Viewer& viewer) {
  const auto end = std::chrono::steady_clock::now() + 10s;
  service::VolumeSnapshot snap;
  while (std::chrono::steady_clock::now() < end) {
    if (viewer.snapshot(snap) && snap.framesApplied > 0) return viewer.render();
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

double meanOf(const renderer::Image& image) {
  double sum = 0.0;
  for (float f : image.rgb) sum += f;
  return sum / static_cast<double>(image.rgb.size());
}

TEST(AreaLightStream, AViewerLightsThePanelExactlyWhenTheStreamSaysSo) {
  const scene::Scene s = cornell();
  renderer::VulkanContext context(test::validatedContext());
  renderer::ViewSetSpec spec;
  std::string error;
  ASSERT_TRUE(renderer::parseViewSet("mono", spec, error)) << error;
  const std::vector<renderer::ViewInfo> views =
      renderer::makeViewSet(renderer::CameraView::fromScene(s), spec, session::viewSetOptions(s, 32, 32));
  const uint32_t dims[3] = {4, 4, 4};
  const float lo[3] = {s.boundsMin.x, s.boundsMin.y, s.boundsMin.z}, hi[3] = {s.boundsMax.x, s.boundsMax.y, s.boundsMax.z};
  const ProbeGrid grid = cellCentredGrid(dims, lo, hi);
  double mean[2] = {0.0, 0.0};
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "rule on" : "rule off");
    ProbeVolume v = makeProbeVolume(grid);
    for (size_t p = 0; p < v.probes.size(); p += kProbeFloats)
      for (int c = 0; c < 3; ++c) v.probes[p + c] = 0.2f;  // the same dim ambient light either way
    v.areaLights = on ? AreaLightRule{kAreaLightRuleVersion, 0.05f} : AreaLightRule{};
    session::ProbeProducer producer(service::hubConfigFor(grid, Representation::Zh3));
    producer.serveVolume(v);
    service::ServerConfig sc;
    sc.listen = "127.0.0.1:0";
    sc.plaintext = true;
    sc.token = "area-light-token";
    const int port = producer.serve(sc);
    session::ViewerConfig vc;
    vc.width = vc.height = 32;
    vc.client.address = "127.0.0.1:" + std::to_string(port);
    vc.client.token = sc.token;
    vc.client.zh3PerPixel = true;
    vc.raster.areaLights.enabled = !on;  // the stream's rule wins over the raster options
    session::Viewer viewer(context, s, views, vc);
    viewer.start();
    ASSERT_TRUE(renderWhenHeld(viewer)) << viewer.clientStats().lastError;
    EXPECT_EQ(viewer.areaLightRule(), v.areaLights);
    EXPECT_EQ(viewer.areaLights().lights.size(), on ? 1u : 0u);  // the ceiling panel, shaded per pixel
    mean[on] = meanOf(viewer.images().at(0));
    viewer.stop();

    // A viewer that asks for the opposite of what the stream says is refused, naming why.
    vc.areaLights = !on;
    session::Viewer wrong(context, s, views, vc);
    wrong.start();
    try {
      renderWhenHeld(wrong);
      ADD_FAILURE() << "a viewer asking for area lights " << (on ? "off" : "on") << " rendered";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(on ? "would be lost" : "count their light twice"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(wrong.images().empty());
    wrong.stop();
    producer.shutdownServer();
  }
  // The same probes: the panel's own direct light is what the rule-on viewer adds.
  EXPECT_GT(mean[1], 1.2 * mean[0]);
}

}  // namespace
}  // namespace probecast
