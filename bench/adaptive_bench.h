// `probecast bench adaptive`: adaptive blending (history rejection) and the noise-aware stream
// against fixed blend weights, on an animated scene: light still → moving → still. Wire bytes per
// probe per frame through the phases, flicker when still, updates to follow a light jump, and the
// image cost of not re-sending noise (PSNR of a raster view against a converged volume).
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/codec/record.h"
#include "probecast/renderer/probe_updater.h"

namespace probecast::bench {

struct AdaptiveBenchOptions {
  std::string sceneSpec = "builtin:cornell";  // an animated scene: t moves its light
  std::array<uint32_t, 3> dims = {4, 4, 4};
  uint32_t samplesPerProbe = 32;
  uint32_t seed = renderer::UpdaterOptions{}.seed;  // of the traced rules' updaters (not the converged truth)
  uint32_t stillUpdates = 96;        // light still at t = 0 (then the same after moving)
  uint32_t movingUpdates = 32;       // light moving by lightStep of t per update
  float lightStep = 0.004f;
  float rejectSigmas = 4.0f;         // the adaptive rule (w_min = 0)
  float neighbourHistory = renderer::UpdaterOptions{}.neighbourHistory;  // and its UpdaterOptions::neighbourHistory
  float changeHistory = renderer::UpdaterOptions{}.changeHistory;        // and UpdaterOptions::changeHistory
  std::vector<float> fixedWMins = {0.02f, 0.05f, 0.25f};  // the fixed rules compared
  float noiseScale = 2.0f;           // the noise-aware stream's c
  uint32_t confirmations = 0;        // and its EncoderOptions::confirmations
  uint32_t refinementInterval = 0;   // and its EncoderOptions::refinementInterval
  // Oracle streams, one per ratio: each knows the converged volume at every update and re-sends the
  // fewest probes that keep the held error within ratio × the full stream's, update by update: about
  // the least any rule that sends estimates needs for that error (costs a converged volume per
  // moving update).
  std::vector<float> oracleErrorRatios;
  // and the weights of its probes' errors: each probe's error energy × its own energy^-exponent
  // (0: absolute, 1: relative, about 0.55: what gamma 2.2 leaves of it in an image); one stream per pair
  std::vector<float> oracleExponents = {0.0f};
  // The streamed rules' updaters trace only the probes that light a surface
  // (UpdaterOptions::surfaceProbesOnly); the converged volumes hold every probe either way.
  bool surfaceProbesOnly = true;
  // The noise-aware stream's view weights (StreamEncoder::setViewWeights): "none"; "footprint":
  // each probe's measured share of the scored views (at the start, on the converged volume; the
  // raster renders the views once per probe); "surface": what a server can work out from the
  // views' geometry alone (renderer::probeViewFootprints); "lit": that weighed by the light the
  // updater's volume holds, recomputed every update (renderer::probeViewSensitivity) and blended
  // over the updates (renderer::blendViewWeights), as the producer does.
  std::string viewWeights = "none";
  int deadzone = 1;                  // both streams
  Representation repr = Representation::Zh3;
  uint32_t jumpUpdates = 48;         // updates charted after the light jump
  uint32_t width = 160, height = 100;
  // Images are scored at the last this many updates of each phase (each against a converged volume
  // at that update's light), the loss paired update by update and averaged: one image alone varies
  // by more than the 0.1 dB a noise-aware stream may lose.
  uint32_t scoredUpdates = 8;
  // The views each scored image is made of ("mono": the scene camera; "stereo", "lf:NxM", "lfh:NxM"
  // around it, view_sets.h): one PSNR over all their pixels.
  std::string scoredViews = "mono";
  // A directory where the converged volumes are kept between runs (empty: none), each named by the
  // scene's content, the grid and the converged volume's settings.
  std::string truthCache;
  // The adaptive rule's streams are measured with this many seeds (seed, seed + 1, ...; the fixed
  // rules, tables and charts with the first): each noise-aware figure's mean and standard error.
  uint32_t streamSeeds = 1;
  // Re-convergence after a light jump, ray budget against brute force (reconvergence.h).
  uint64_t raysPerUpdate = 0;        // 0 = active probes × samplesPerProbe
  float viewYfov = 0.03f;            // the viewer whose probes are scored (builtin:cornell 4³: 16 of 64 probes)
  bool reconvergenceOnly = false;    // measure only that
  uint32_t reconvergenceUpdates = 160;  // updates measured after its jump (brute force needs over 100)
  // Seeds it is measured with (seed, seed + 1, ...): one jump's ratio is a first passage of a noisy
  // error curve, so the summary takes the median over these.
  uint32_t reconvergenceSeeds = 5;

  renderer::ContextOptions context;
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct AdaptiveBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svgBytes;  // bytes per probe per frame through still → moving → still
  std::string svgJump;   // error against updates after a light jump
};

AdaptiveBenchResult runAdaptiveBench(const AdaptiveBenchOptions& options);

}  // namespace probecast::bench
