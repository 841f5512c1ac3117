// `probecast bench stream`: the service under N subscribers on loopback, with a moving light.
// The server (a probe producer: hub, encoder, gRPC) runs in a child process so its CPU time is its
// own; call it before this process starts gRPC (the children are forked first).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace probecast::bench {

struct StreamBenchOptions {
  std::vector<int> subscribers = {1, 10, 100};
  double hz = 10.0;
  double seconds = 5.0;
  uint64_t budgetBytesPerSecond = 0;  // per subscriber; 0 = unlimited
  std::string repr = "zh3";
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct StreamBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;
};

StreamBenchResult runStreamBench(const StreamBenchOptions& options);

// Lighting frame `frame` of the benchmark's volume: 32 × 8 × 32 probes (x fastest) lit by a light
// circling above them (analytic SH), 27 floats per probe.
constexpr uint16_t kLightingGrid[3] = {32, 8, 32};
void lightingFrame(int frame, std::vector<float>& probes);

}  // namespace probecast::bench
