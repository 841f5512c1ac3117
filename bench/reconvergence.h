// Re-convergence after a light jump with a ray budget against brute force (bench adaptive): how
// many updates the probes a viewer sees take to get back within the error a converged volume had
// before the jump, when the updater spends its rays by need (UpdaterOptions::raysPerUpdate) and
// when it traces every probe at a fixed spp, with the same rays per update.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/reference_camera.h"

namespace probecast::bench {

struct ReconvergenceOptions {
  std::string sceneSpec = "builtin:cornell";  // t moves its light
  std::array<uint32_t, 3> dims = {4, 4, 4};
  uint32_t samplesPerProbe = 32;   // brute force's spp; the budget's nominal update
  uint64_t raysPerUpdate = 0;      // both; 0 = active probes × samplesPerProbe
  float viewYfov = 0.03f;          // the viewer: the scene's camera with this field of view (radians)
  uint32_t convergeUpdates = 24;   // light still at t = 0 before the jump
  uint32_t afterUpdates = 160;     // updates measured after the jump to t = 0.5
  float rejectSigmas = 4.0f;       // both (w_min 0)
  float neighbourHistory = renderer::UpdaterOptions{}.neighbourHistory;  // both
  float changeHistory = renderer::UpdaterOptions{}.changeHistory;        // both
  uint32_t seed = 1;                                                      // both updaters'
};

struct ReconvergenceResult {
  uint64_t raysPerUpdate = 0;
  uint32_t inViewProbes = 0, activeProbes = 0;
  double threshold = 0;  // in-view error of brute force just before the jump (against the t = 0 truth)
  std::vector<double> adaptiveError, bruteForceError;  // in view, against the t = 0.5 truth, per update after
  int adaptiveUpdates = -1, bruteForceUpdates = -1;    // first update after the jump within threshold (-1: never)
  double ratio = -1;  // adaptiveUpdates / bruteForceUpdates (-1 when either never got there)
  // When only the budget got there: adaptiveUpdates / (updates measured + 1), above the ratio (-1 otherwise).
  double ratioAtMost = -1;
  nlohmann::json json() const;
};

ReconvergenceResult measureReconvergence(renderer::VulkanContext& context, const ReconvergenceOptions& options);

}  // namespace probecast::bench
