// `probecast bench update`: the Vulkan probe updater's speed (rays/s, ms per update), its
// convergence against a high-sample reference, and flicker against w_min.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/probe_updater.h"

namespace probecast::bench {

struct UpdateBenchOptions {
  scene::Scene scene;
  ProbeGrid grid;
  renderer::UpdaterOptions updater;     // samplesPerProbe, bounces, seed, clamp
  renderer::ContextOptions context;
  uint32_t updates = 16;                // convergence and flicker runs
  uint32_t referenceSamples = 16384;    // per probe, for the reference volume
  std::vector<float> minBlendWeights = {0.02f, 0.05f, 0.1f, 0.25f};
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct UpdateBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;
};

UpdateBenchResult runUpdateBench(const UpdateBenchOptions& options);

// Relative irradiance difference between two probe sets, exact over the sphere (SH orthonormality),
// pooled over RGB and the probes where `active` is set.
double irradianceRmseRel(const float* test, const float* reference, const uint8_t* active, uint32_t count);
// The same difference taken relative to each probe's own energy, then the RMS over the probes (a
// dim probe counts as much as a bright one, as in an image after tone mapping); probes without
// energy in `reference` are left out.
double irradianceRmseRelPerProbe(const float* test, const float* reference, const uint8_t* active, uint32_t count);

}  // namespace probecast::bench
