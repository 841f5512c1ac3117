// `probecast bench stream`: the service under N subscribers on loopback, with a moving light.
// The server (a probe producer: hub, encoder, gRPC) and the load (light subscribers, load_client.h)
// run in processes of their own, so each one's CPU time and memory is its own. This process forks
// them and never starts gRPC itself (gRPC cannot be forked once it runs).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace probecast::bench {

// The benchmark volume's probes per axis (lightingFrame).
constexpr uint16_t kLightingGrid[3] = {32, 8, 32};

struct StreamBenchOptions {
  std::vector<int> subscribers = {1, 100, 1000};
  double hz = 30.0;
  double seconds = 10.0;  // measured, per subscriber count
  uint64_t budgetBytesPerSecond = 0;  // per subscriber; 0 = unlimited
  std::string repr = "zh3";
  int subscribersPerLoadProcess = 250;
  // 0: subscribers connect to the producer's server. N > 0: the producer publishes to a
  // nats-server (JetStream, started for the run) and N edges serve the subscribers, split evenly.
  int edges = 0;
  int sampleEvery = 50;  // 1 in this many subscribers decodes fully (subscriber 0 always does)
  int ackIntervalMs = 100;  // load clients ack the newest frame at most this often (0: every frame)
  bool linkPacing = true;   // load clients ack on request and the server paces them to their link
  std::array<uint16_t, 3> grid = {kLightingGrid[0], kLightingGrid[1], kLightingGrid[2]};  // probes per axis, 1 m apart
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct StreamBenchResult {
  nlohmann::json json;
  std::string table;
  std::string svg;
  // Empty, or what went wrong (wrong volumes, sequence or CRC errors): the outputs are still
  // written, and the command then fails with this.
  std::string failure;
};

StreamBenchResult runStreamBench(const StreamBenchOptions& options);

// Lighting frame `frame` of the benchmark's volume: 32 × 8 × 32 probes (x fastest) lit by a light
// circling above them (analytic SH), 27 floats per probe.
// Other grids (`dims`, probes 1 m apart) get the same light over their own centre, its circle's
// radius scaled with the grid's width.
void lightingFrame(int frame, std::vector<float>& probes, std::array<uint16_t, 3> dims = {32, 8, 32});

}  // namespace probecast::bench
