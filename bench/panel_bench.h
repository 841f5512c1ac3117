// `probecast bench panel`: what one Looking Glass panel frame costs the raster client, phase by
// phase (its view set drawn and read back, the quilt put together, the interleave), for several
// ways of drawing the views, and how far each way's panel image is from the panel of the same
// views drawn at full quality (4 × 4 supersampling with 4× MSAA).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/looking_glass.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"

namespace probecast::bench {

// One way of drawing a panel's views.
struct PanelWay {
  std::string name;
  uint32_t samplesPerSide = 1;
  uint32_t msaa = 4;
  double viewScaleX = 1.0, viewScaleY = 1.0;  // of the model's view size
  renderer::ViewPasses passes = renderer::ViewPasses::PerView;
};

// The named ways --ways chooses from: msaa4 (the viewers' default), msaa1, half (views of half
// the size each side, 4× MSAA), narrow (half the width, the whole height: a lenticule shows a
// view only a few hundred columns across), multiview (4× MSAA, chunks of views per pass), ss2
// (2 × 2 supersampling with 4× MSAA); false with a message naming the known ones.
bool panelWay(const std::string& name, PanelWay& out, std::string& error);

struct PanelBenchOptions {
  scene::Scene scene;
  ProbeGrid grid;
  renderer::UpdaterOptions updater;
  renderer::ContextOptions context;
  renderer::RasterOptions raster;  // shadows, visibility, area lights; samples and passes per way
  renderer::LookingGlassCalibration calibration;
  uint32_t viewWidth = 0, viewHeight = 0;  // 0: the model's view size
  uint32_t updates = 8;                    // probe updates before drawing
  uint32_t repeats = 3;                    // timed frames per way (the median is reported)
  std::vector<PanelWay> ways;
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct PanelBenchResult {
  nlohmann::json json;
  std::string table;
};

// Throws std::invalid_argument for options that cannot run (no way, no repeat).
PanelBenchResult runPanelBench(const PanelBenchOptions& options);

}  // namespace probecast::bench
