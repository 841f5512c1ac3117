// `probecast demo` in two parts: running the session (a server tracing and streaming the scene
// while its light moves, two viewers re-rendering as lighting arrives, then settling) and
// writing the report (references, metrics, images, charts, suites, report.md / report.json).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"
#include "probecast/session/head_trace.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/viewer.h"
#include "scene_options.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::app {

using DemoClock = std::chrono::steady_clock;

struct DemoOptions {
  std::string out = "out";
  std::string scene = "builtin:cornell";
  double seconds = 24.0;        // streaming with the light moving
  double rate = 0.025;  // scene seconds per second while streaming (built-ins turn their light once per scene second)
  uint32_t spp = 64;            // updater samples per probe per update
  GridOptions grid;  // --grid only (no --bounds), 2…64 per axis
  std::string repr = "zh3";
  std::string lightField = "lf:5x5";
  uint32_t settleUpdates = 24;  // updates with the light frozen before the comparison
  NoiseRuleCli noise;           // the hub's noise rule, as given
  EncoderOptions encoder;       // its scale and refinement interval once checked (NoiseRuleCli::apply)
  uint32_t referenceSpp = 1024;  // two halves of different seeds: the reference's own noise floor
  std::string referenceCache;    // empty: bench::defaultReferenceCacheDir()
  uint64_t lightFieldBudget = 6 * 1024;  // bytes/s: the display sits on a thin link
  bool skipSuites = false;               // no pipeline benchmark or stability suite in the report
  std::string video = "on";              // on: the report sets the stream against video of the viewers' views
  std::string ffmpeg = "ffmpeg";         // for that comparison
  std::string headTrace = session::kBuiltinHeadTrace;  // the headset's camera there turns as a head did; "none": still
  std::shared_ptr<const session::HeadTrace> trace;     // read from `headTrace` before anything starts
  EnvironmentOptions environment;        // --environment/--sky...: the server's, the viewers' and the references' sky
  std::shared_ptr<const renderer::Environment> sky;  // loaded from `environment` before anything starts
  bool visibility = true;                // viewers weigh probes by visibility (RasterOptions)
  uint32_t supersample = renderer::RasterOptions{}.samplesPerSide;  // the viewers' raster samples per pixel side
  uint32_t msaa = renderer::RasterOptions{}.msaaSamples;            // and their MSAA samples
  uint32_t anisotropy = renderer::RasterOptions{}.anisotropy;       // and texture taps along a footprint
  AreaLightCli areaLights;               // the server's rule; the viewers follow what the stream says
  DeviceOptions device;                     // --device: the server's and the viewers' Vulkan device
};

struct DemoViewer {
  std::string name, viewSet;
  uint32_t width = 0, height = 0;
  uint64_t budget = 0;
  renderer::ViewSetSpec spec;
  std::unique_ptr<session::Viewer> viewer;
  std::vector<imaging::ChartPoint> bandwidth;  // (seconds, bytes/s over the last interval)
  uint64_t lastBytes = 0;
  uint64_t streamBytes = 0;  // received while the light moved
  bool converged = false;    // ended holding the server's volume bit for bit
};

// Everything the report needs from the session; the Vulkan contexts outlive what uses them.
struct DemoRun {
  DemoClock::time_point wallStart;
  std::unique_ptr<renderer::VulkanContext> serverContext, viewerContext;
  std::unique_ptr<session::ProbeProducer> producer;
  scene::Scene scene0;
  ProbeGrid grid;
  std::vector<DemoViewer> viewers;  // the headset, the light-field display
  nlohmann::json moments = nlohmann::json::array();
  nlohmann::json phases;
  double streamSeconds = 0.0;
  float finalT = 0.0f;
};

// Streams with the light moving, freezes it, lets the probes settle and waits for both viewers
// to hold the server's volume; writes the images of three moments to o.out.
void runDemoSession(const DemoOptions& o, DemoRun& run);
// Renders the final views, compares them with references, runs the suites (unless skipped),
// writes report.json, report.md, charts and images to o.out, and prints the summary.
void writeDemoReport(const DemoOptions& o, DemoRun& run);

// The pipeline benchmark (small) and the stability suite, written next to the report (in `dir`);
// their report sections (demo_suites.cpp).
std::string runSuites(const DemoOptions& o, const std::string& dir, const scene::Scene& finalScene, float finalT,
                      const ProbeGrid& grid, nlohmann::json& phases);
// The stream against video of the viewers' own views, written next to the report; its report
// section (without ffmpeg, a section that says so).
std::string runVideoComparison(const DemoOptions& o, const DemoRun& run, const std::string& dir, nlohmann::json& report);

double secondsSince(DemoClock::time_point t0);
// A viewer's current images on disk: a stereo pair side by side, or a light-field quilt.
void writeViewerImages(const std::string& prefix, const DemoViewer& v, const std::vector<renderer::Image>& images);

}  // namespace probecast::app
