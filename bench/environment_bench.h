// `probecast bench environment`: how fast the reference path tracer converges under an
// environment map with a small bright sun, with next-event estimation importance-sampling the map
// (MIS with the BSDF) against reaching it by BSDF sampling only. RMS error against a reference
// rendered with importance sampling at many samples per pixel, per spp, for both.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/environment.h"
#include "probecast/renderer/reference_camera.h"

namespace probecast::bench {

struct EnvironmentBenchOptions {
  scene::Scene scene;
  renderer::CameraView camera;
  std::shared_ptr<const renderer::Environment> environment;
  renderer::ContextOptions context;
  uint32_t width = 48, height = 32;
  uint32_t maxBounces = 3;
  uint32_t referenceSpp = 4096;
  std::vector<uint32_t> spps = {1, 2, 4, 8, 16, 32, 64, 128};
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct EnvironmentBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;  // RMS error against spp, both strategies, log-log
};

// A sunlit yard for the benchmark: a 20 m grey ground and a 1 m white box, camera looking at it.
scene::Scene sunlitYard(renderer::CameraView& camera);
// bench::builtinEnvMaps()'s sunny sky (a 2.6° sun of radiance 5000 over a blue sky) as an Environment.
std::shared_ptr<renderer::Environment> builtinSunSky();

EnvironmentBenchResult runEnvironmentBench(const EnvironmentBenchOptions& options);

}  // namespace probecast::bench
