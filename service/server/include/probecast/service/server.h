// The gRPC ProbeStream server: a thin adapter from the ProbeHub to the wire. One reactor per
// subscriber with one write in flight, so gRPC's flow control paces each stream.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "probecast/service/latency_histogram.h"
#include "probecast/service/probe_hub.h"
#include "probecast/service/scene_package.h"

namespace probecast::service {

struct ServerConfig {
  std::string listen = "127.0.0.1:0";  // host:port; port 0 picks a free one
  std::string token;                    // bearer token required on every call
  bool noAuth = false;                  // must be set to serve without a token (anyone may subscribe)
  std::string tlsCertPem;               // PEM contents; with tlsKeyPem enables TLS
  std::string tlsKeyPem;
  bool plaintext = false;               // must be set to serve without TLS
  uint32_t maxSubscribers = 1024;
  uint32_t maxViews = kMaxViewsPerSet;  // per view update: any view set a renderer draws
  // Largest client message accepted. A view is about 83 bytes on the wire (16 packed floats and
  // three eye floats), so kMaxViewsPerSet views take about 21 KiB. A Hello may add 14 bytes per
  // brick of the volume for the versions a resuming client holds.
  uint32_t maxMessageBytes = 64 * 1024;
  // Keepalive: clients may ping this often (ClientConfig::keepaliveMs must not be shorter, or the
  // server ends their connections); the server pings its own clients every keepaliveMs and drops
  // one that does not answer within keepaliveTimeoutMs, so a vanished subscriber frees its slot.
  int minClientPingMs = 5000;
  int keepaliveMs = 30000;
  int keepaliveTimeoutMs = 10000;
  // The server ticks the hub this often (ms), so byte budgets refill and wake their subscribers
  // even while nothing new is published.
  static constexpr int kTickMs = 50;
  // Link-aware pacing: a subscriber that acks every frame (Hello.acks_every_frame, as ProbeClient
  // does) is kept within what its link delivers, measured from its acks (ProbeHub::addSubscriber).
  // Off: every subscriber is sent frames as fast as the transport takes them.
  bool linkPacing = true;
  // The scene package GetScene delivers (its files read from their sources on this machine); none:
  // GetScene answers NOT_FOUND. It should be the one the hub's descriptions name.
  std::shared_ptr<const ScenePackage> scene;
};

class ProbeServer {
 public:
  // Throws std::runtime_error when the configuration is unsafe (no TLS without plaintext, no token
  // without noAuth, or a token with noAuth) or the port cannot be bound.
  ProbeServer(const ServerConfig& config, ProbeHub& hub);
  ~ProbeServer();
  ProbeServer(const ProbeServer&) = delete;
  ProbeServer& operator=(const ProbeServer&) = delete;

  int port() const;
  void shutdown();
  // Replaces the scene package GetScene delivers (ServerConfig::scene), e.g. once an edge has it.
  void setScene(std::shared_ptr<const ScenePackage> scene);

  // Instrumentation for load tests: the time from the publish of a frame's newest lighting
  // (OutgoingFrame::serverTimeUs, system clock) to gRPC's write-done for it, over all frames
  // written since the last call, which starts a new count.
  LatencyHistogram takeFrameWriteLatency();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::service
