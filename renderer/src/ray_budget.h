// Spending a ray budget over probes by need (UpdaterOptions::raysPerUpdate, probe_updater.h).
//
// A share of the budget refreshes the probes traced longest ago, one lane's worth each, so every
// probe is traced now and then whatever anyone sees. The rest goes, one lane's worth at a time, to
// the probe whose weighted relative variance it lowers most: a history of n nominal updates with
// relative variance s² per update has variance s²/n, and m more samples (δ = m / nominal updates)
// lower it by s² (1/n − 1/(n + δ)), weighted by whether a viewer sees the probe. A probe that has
// just restarted (small n), one whose last estimate was held back, or a noisy one wins; a
// converged still one seldom does.
#pragma once

#include <cstdint>
#include <span>

namespace probecast::renderer {

struct ProbeNeed {
  float viewWeight = 1.0f;        // 1: inside a subscriber's view; 0: outside every one
  float relativeVariance = 1.0f;  // σ² of one nominal update's estimate over the probe's signal²
  float historyWeight = 0.0f;     // n of the history (nominal updates); 0 = never traced
  bool suspect = false;           // its last estimate was held back: the next one decides
  uint32_t age = 0;               // updates since it was last traced
};

struct RayBudgetRule {
  uint64_t rays = 0;               // per update
  uint32_t lane = 32;              // samples per probe come in multiples of this
  uint32_t nominalSamples = 32;    // a history weight of 1 is this many samples
  uint32_t maxSamples = 256;       // per probe and update (a multiple of lane)
  float refreshShare = 0.1f;       // of the budget, to the probes traced longest ago
  float outOfViewWeight = 0.05f;   // view weight floor: probes nobody sees still converge, slowly
};

// Samples per probe (multiples of rule.lane, at most rule.maxSamples) into `samples`; returns
// their sum, which is the budget rounded down to whole lanes (at least one lane) and capped by
// what every probe at maxSamples would take.
uint64_t allocateRays(std::span<const ProbeNeed> needs, const RayBudgetRule& rule, uint32_t* samples);

}  // namespace probecast::renderer
