// `probecast bench scene`: the seeds' table for one scene — probe update ms, raster ms per view,
// and per representation (l1, zh3h, zh3, l2, fp16) PSNR/SSIM of every view against a cached
// path-traced reference (with its noise floor) and against the float-probe render of the same
// view (the codec's own loss).
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"

namespace probecast::bench {

struct SceneBenchOptions {
  scene::Scene scene;
  float t = 0.0f;
  ProbeGrid grid;
  renderer::UpdaterOptions updater;  // its environment lights the probes, the reference and the background
  renderer::ContextOptions context;
  renderer::RasterOptions raster;   // samplesPerSide > 1: each pixel averages its footprint, like the reference's
  uint32_t updates = 8;              // probe updates, each timed
  std::string views = "mono";        // mono, stereo, lf:NxM (renderer/view_sets.h)
  uint32_t width = 160, height = 100;
  uint32_t repeats = 3;              // timed renders of the view set per representation (median)
  uint32_t referenceSpp = 4096;
  uint32_t referenceBounces = 8;
  uint32_t referenceSeed = 1;
  std::string referenceCache;        // empty: defaultReferenceCacheDir()
  std::string imagesDir;             // empty: no PNGs
  float exposure = 1.0f;             // scale of the PNGs only (filmic tone map)
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct SceneBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;  // mean PSNR against ms per view, one point per representation
};

// Throws std::invalid_argument with a message naming the option for nonsense the CLI's own range
// checks cannot see (a view set that does not parse, a reference of more samples than can finish).
void checkSceneBenchOptions(const SceneBenchOptions& options);
SceneBenchResult runSceneBench(const SceneBenchOptions& options);

}  // namespace probecast::bench
