// The client library (no Vulkan): subscribes, sends views, decodes into a local probe volume, keeps
// the last volume when the network drops, reconnects with back-off and resumes by telling the
// server what it holds. Given several servers (edges of one producer), it moves to the next when
// one is unavailable or its connection dies, and resumes there with its epoch and held versions.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/codec/stream.h"

namespace probecast::service {

struct ClientConfig {
  std::string address;                  // host:port
  // Servers to fail over between, in order (edges of one producer); empty: `address` alone.
  std::vector<std::string> addresses;
  std::string token;                    // bearer token
  bool tls = false;
  std::string rootCertPem;              // trusted root for TLS (empty: system roots)
  std::string tlsServerName;            // override of the name checked against the certificate
  uint64_t budgetBytesPerSecond = 0;    // 0 = unlimited
  std::string name = "probecast-client";
  int reconnectMinMs = 50;   // back-off after every server has failed in turn
  int reconnectMaxMs = 2000;
  // HTTP/2 pings on the connection: a server that does not answer one within keepaliveTimeoutMs
  // is gone (a frozen or unplugged machine never closes its TCP connections), and the client
  // fails over. The server accepts pings this often (ServerConfig::minClientPingMs).
  int keepaliveMs = 10000;
  int keepaliveTimeoutMs = 5000;
  // zh3h streams: decode L1 only (ProbeVolume::zh3PerPixel) so a renderer can interpolate first
  // and hallucinate per pixel; false: hallucinate per probe when decoding.
  bool zh3PerPixel = false;
  // The representation wanted (none: the server's). A server transcodes its stream to a coarser
  // one (canTranscode in probe_hub.h) and refuses a finer one (INVALID_ARGUMENT: fatal); a
  // description of another representation is refused and the server tried again later.
  std::optional<Representation> representation;
  // Acks (of the newest applied frame) go at most this often; 0: one per frame. The server reads
  // them for its statistics (frames_acked, ack_rtt_us) and nothing else, and each is a message
  // it must read: a thousand viewers acking every frame at 30 Hz would double its messages. While
  // no frames come, the server's frames_acked may trail the last frame applied.
  int ackIntervalMs = 100;
};

struct VolumeSnapshot {
  ProbeVolume volume;           // the last good volume (decodedFrom: the stream's representation;
                                // offsets and areaLights: the description's)
  StreamLayout layout;          // the stream's grid, brick edge and representation
  uint32_t framesApplied = 0;
  uint64_t newestServerTimeUs = 0;
};

struct ClientStats {
  bool connected = false;
  uint32_t connects = 0;          // successful subscriptions (1 + resumes)
  uint32_t failovers = 0;         // moves to the next server after one failed
  std::string address;            // the server subscribed to last
  uint32_t framesApplied = 0;
  uint32_t framesRejected = 0;    // frames the decoder refused (state kept)
  uint64_t bytesReceived = 0;     // payload bytes
  uint64_t keyframesReceived = 0; // brick sections in applied frames that were keyframes
  uint64_t deltasReceived = 0;    // and that were deltas
  std::string lastError;          // last status or decode error
  bool fatal = false;             // the server refused us (auth, bad request): no more retries
  uint32_t statsReceived = 0;     // Stats messages from the server
  uint64_t serverBytesSent = 0;   // as the server counted them (latest Stats)
  uint32_t serverBricksBehind = 0;
  uint32_t serverFramesAcked = 0; // our acks as the server counted them
  uint32_t serverAckRttUs = 0;    // frame → ack round trip as the server measured it
};

class ProbeClient {
 public:
  explicit ProbeClient(const ClientConfig& config);
  ~ProbeClient();  // stops
  ProbeClient(const ProbeClient&) = delete;
  ProbeClient& operator=(const ProbeClient&) = delete;

  void start();
  void stop();
  // Replaces the views sent to the server (now, and again after every reconnect).
  void setViews(std::vector<View> views);
  // Copies the current volume (into `out`'s storage); false until a volume description has arrived.
  bool snapshot(VolumeSnapshot& out) const;
  ClientStats stats() const;
  // Cuts the current connection (as a network fault would); the client reconnects and resumes.
  void dropConnection();
  // Produce→decoded latencies of the frames applied so far (microseconds, server and client
  // clocks: meaningful on one machine or with synchronised clocks), the most recent 4096.
  std::vector<uint32_t> latenciesUs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::service
