// `probecast bench raster`: the raster client's speed per view for view sets of 1…48 views (one
// pass per view and multiview chunks), and its image quality per codec representation against
// the reference path tracer (PSNR, SSIM after plain gamma 2.2).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"
#include "harness.h"
#include "probecast/renderer/raster_client.h"

namespace probecast::bench {

struct RasterBenchOptions {
  scene::Scene scene;
  ProbeGrid grid;
  renderer::UpdaterOptions updater;
  renderer::ContextOptions context;
  renderer::RasterOptions raster = singleSampleRaster();  // `passes` is measured both ways
  uint32_t updates = 8;            // probe updates before rendering
  uint32_t width = 320, height = 200;
  std::vector<std::string> viewSets = {"mono", "stereo", "lf:2x2", "lf:4x4", "lf:5x5", "lf:8x6"};
  uint32_t repeats = 5;            // timed renders per case (the median is reported)
  // Probe volumes whose update (setProbes) is timed, 4 × repeats times each.
  std::vector<glm::uvec3> uploadGrids = {{8, 8, 8}, {32, 8, 32}};
  uint32_t referenceSpp = 256;
  std::string referenceCache;  // empty: defaultReferenceCacheDir() (harness.h)
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct RasterBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;       // PSNR against ms per view, one point per representation
  std::string svgViews;  // ms per view against views per set, both ways of drawing them
};

RasterBenchResult runRasterBench(const RasterBenchOptions& options);

}  // namespace probecast::bench
