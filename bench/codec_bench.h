// `probecast bench codec`: size against irradiance accuracy and speed for every representation,
// and the temporal coder on a moving-light sequence for several dead-zones.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "envmap.h"

namespace probecast::bench {

struct CodecBenchOptions {
  std::vector<EnvMap> maps;
  // Optional baked probes (probecast bake): measured against their own float L2, active ones only.
  std::string volumeName;
  std::vector<float> volumeProbes;   // 27 floats per probe
  std::vector<uint8_t> volumeActive;
  std::array<uint32_t, 3> volumeDims{0, 0, 0};  // its grid (for the per-brick representation keyframes)
  std::vector<int> deadzones = {0, 1, 2, 4, 8};
  // Per-brick representation (EncoderOptions::errorBound) on the temporal sequence: an l2 stream at
  // dead-zone 1 with each bound.
  std::vector<float> errorBounds = {0.02f, 0.05f, 0.1f};
  int frames = 60;         // temporal sequence length
  int normals = 2048;      // equal-area directions for the brute-force irradiance
  int throughputProbes = 65536;
  int repeats = 7;         // timing repeats; the median is reported
  std::string command;     // recorded in the JSON and the chart
  std::function<void(const std::string&)> progress;
};

struct CodecBenchResult {
  nlohmann::json json;
  std::string table;  // readable summary
  std::string svg;    // error against bytes
};

CodecBenchResult runCodecBench(const CodecBenchOptions& options);

}  // namespace probecast::bench
