// `probecast bench pipeline`: image quality (PSNR against the reference path tracer) against what
// each stage costs — wire bytes per second (representation × dead-zone, light moving), update time
// (samples per probe × bounces), and bytes per probe (representation) — on one scene, one view, in
// one run, with the Pareto front of each marked.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"

namespace probecast::bench {

struct PipelineBenchOptions {
  scene::Scene scene;          // an animated built-in scene moves its light with t
  std::string sceneSpec;       // to re-load the scene at other t
  ProbeGrid grid;
  renderer::ContextOptions context;
  uint32_t width = 160, height = 100;
  uint32_t referenceSpp = 128;
  std::string referenceCache;  // empty: defaultReferenceCacheDir() (harness.h)
  float t = 0.25f;             // where the light ends (the reference's moment)
  uint32_t streamFrames = 24;  // moving-light frames for the wire-bytes part
  double hz = 10.0;            // lighting updates per second the bytes are quoted at
  std::vector<uint32_t> spps = {32, 64, 128, 256};  // the updater rounds up to a multiple of 32
  std::vector<uint32_t> bounces = {1, 2, 4};
  std::vector<int> deadzones = {0, 1, 4, 16};
  uint32_t updates = 4;        // updates per configuration of the update-cost part
  std::shared_ptr<const renderer::Environment> environment;  // lights every tracer; the raster's background
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct PipelineBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svgBytes;    // PSNR against wire bytes/s
  std::string svgUpdate;   // PSNR against update ms
  std::string svgRepr;     // PSNR against bytes per probe
};

PipelineBenchResult runPipelineBench(const PipelineBenchOptions& options);

struct ParetoPoint {
  double cost = 0;
  double quality = 0;
};
// Indices of the points no other point beats on both (lower or equal cost and higher or equal
// quality, one of them strictly), in order of increasing cost.
std::vector<size_t> paretoFront(const std::vector<ParetoPoint>& points);

}  // namespace probecast::bench
