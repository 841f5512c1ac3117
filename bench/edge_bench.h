// `probecast bench edge`: the probe bus against direct serving. A producer (in a child process)
// serves its clients directly and publishes to a nats-server; two edges (child processes) serve
// theirs from the bus. Measured: produce → decoded latency direct and through NATS + an edge,
// the time from an edge's death (SIGKILL) to its clients' first frame from the other edge, and
// whether every client ends bit-identical to a direct one. Call it before this process starts
// gRPC (the children are forked first).
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace probecast::bench {

struct EdgeBenchOptions {
  int clients = 10;       // per phase: direct, then through the edges
  double hz = 30.0;
  double seconds = 5.0;   // per latency phase
  int kills = 3;          // edges killed one after another, a fresh one started in its place
  std::string repr = "zh3";
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct EdgeBenchResult {
  nlohmann::json json;
  std::string table;
};

EdgeBenchResult runEdgeBench(const EdgeBenchOptions& options);

}  // namespace probecast::bench
