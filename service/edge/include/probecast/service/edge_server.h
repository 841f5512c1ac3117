// A stateless edge: the ProbeStream service (auth, TLS, limits, priority, budgets, resume) fed
// from the probe bus instead of an encoder of its own. Epoch and brick versions are the
// producer's, so a subscriber moves between edges with what it holds; a new producer epoch ends
// every stream so clients subscribe again. An edge keeps nothing a restart would miss: it
// starts from the newest message of every brick the bus retains.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "probecast/service/bus_nats.h"
#include "probecast/service/client.h"
#include "probecast/service/probe_hub.h"
#include "probecast/service/server.h"

namespace probecast::service {

struct EdgeConfig {
  BusConfig bus;
  ServerConfig server;
  HubConfig hub;  // priority and burst; layout, bounds and encoder come from the bus
  // Scene delivery: the bus names the producer's scene; the edge serves its package (GetScene)
  // from `sceneCache` when it holds it, else fetched once from `sceneSource` (the producer or
  // another edge) into the cache. Neither: built-in scenes only (their manifest is the package).
  std::filesystem::path sceneCache;
  std::optional<ClientConfig> sceneSource;
  uint64_t sceneMaxBytes = uint64_t{4} << 30;
};

struct EdgeStats {
  bool busConnected = false;
  uint64_t received = 0;  // bus messages
  uint64_t applied = 0;   // brick versions kept
  uint64_t stale = 0;     // redeliveries of versions already held
  uint64_t refused = 0;   // malformed messages or sections that do not decode (not applied)
  uint32_t epochs = 0;    // producer epochs seen
  uint32_t subscribes = 0;  // times the bus subscription was (re)made
  std::string lastError;
  std::string scene;        // the scene package it delivers (ScenePackage::describe), empty: none yet
  SceneFetch sceneFetch;    // how it got it
};

class EdgeServer {
 public:
  // Listens at once (answering UNAVAILABLE until the bus has delivered a volume) and subscribes
  // in the background. Throws like ProbeServer, or std::invalid_argument for a bad bus config.
  explicit EdgeServer(const EdgeConfig& config);
  ~EdgeServer();
  EdgeServer(const EdgeServer&) = delete;
  EdgeServer& operator=(const EdgeServer&) = delete;

  int port() const;
  EdgeStats stats() const;
  const ProbeHub& hub() const;
  // The gRPC server's frame write latencies since the last call (ProbeServer::takeFrameWriteLatency).
  LatencyHistogram takeFrameWriteLatency();
  // Ends every stream and stops listening, then leaves the bus.
  void shutdown();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::service
