// `probecast bench motion`: probes while geometry moves. An animated scene is held still, then
// played at a fixed scene step per update, then held still again; at every update the bench
// records the updater's time (with setScene's acceleration-structure build and the classification
// of the probes near moved geometry), the probes' error against a converged volume of that scene
// time, the bytes the stream encoder sends per probe, and the raster client's visibility rebuild.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/codec/stream.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/vulkan_context.h"

namespace probecast::bench {

struct MotionBenchOptions {
  std::string sceneSpec;  // an animated glTF file or a built-in
  ProbeGrid grid;
  renderer::UpdaterOptions updater;
  renderer::ContextOptions context;
  Representation repr = Representation::Zh3;
  EncoderOptions encoder;  // as serve's (its deadzone and noise rule)
  double start = 0.0;        // scene time of the still phases before the motion
  double step = 1.0 / 12.0;  // scene seconds per update while moving
  uint32_t stillBefore = 8, moving = 16, stillAfter = 12;
  uint32_t referenceSamples = 1024;  // per probe and update of each time's converged volume (4 updates)
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct MotionBenchResult {
  nlohmann::json json;
  std::string table;
};

// Throws std::invalid_argument for options that cannot run (no probes, no moving updates, steps
// that are not finite and positive).
MotionBenchResult runMotionBench(const MotionBenchOptions& options);

}  // namespace probecast::bench
