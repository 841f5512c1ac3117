// The client library (no Vulkan): subscribes, sends views, decodes into a local probe volume, keeps
// the last volume when the network drops, reconnects with back-off and resumes by telling the
// server what it holds. Given several servers (edges of one producer), it moves to the next when
// one is unavailable or its connection dies, and resumes there with its epoch and held versions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/codec/stream.h"
#include "probecast/service/bus_format.h"
#include "probecast/service/scene_package.h"

namespace probecast::service {

// The most connection attempts a client has open at once (ClientConfig::connectRaceMs).
inline constexpr int kConnectRaceAttempts = 32;

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
  // Without link pacing (below), acks (of the newest applied frame) go at most this often; 0: one
  // per frame. The server then reads them for its statistics (frames_acked, ack_rtt_us) only, and
  // while no frames come its frames_acked may trail the last frame applied.
  int ackIntervalMs = 100;
  // Link-aware pacing: the client acks every frame at once (ackIntervalMs does not apply), and a
  // server that paces (ServerConfig::linkPacing) keeps the stream within what the link
  // delivers, measured from those acks; the frames it sends are then the newest, best-first
  // bricks instead of a queue in the network's buffers. Off: the server sends as fast as its
  // transport takes frames (and the client acks every ackIntervalMs only).
  bool linkPacing = true;
  // A server that promises a message at least every so often (Stats heartbeat_ms: it does for a
  // client that acks every frame) and says nothing for silenceMs has a cut connection: a link outage
  // stalls TCP, whose retransmissions back off for seconds after the link returns. The client
  // drops it and connects afresh at once, giving each new attempt reconnectSilenceMs to connect
  // (connectRaceMs) and again to answer once connected (every other attempt in a row that gets no
  // answer has twice as long).
  // 0: wait for TCP and the keepalive.
  int silenceMs = 3000;
  int reconnectSilenceMs = 2000;
  // Overlapping connection attempts after a cut for silence (the link is suspect): while no
  // connection to the server is up (TCP, TLS and HTTP/2), another is begun every connectRaceMs; the
  // first to come up is kept and the others dropped. A link back from an outage is then met by the
  // next attempt's SYN, not by TCP's retransmission a second or more later, and a lost handshake
  // packet costs one interval. When none comes up within reconnectSilenceMs (twice that every
  // other time in a row), it counts as unanswered and the next server is tried the same way. At
  // most kConnectRaceAttempts are open (the oldest is dropped), none lives past its race by more
  // than a second; the interval doubles after every twice as many, up to 4x. 0: one attempt at a
  // time, under the watchdog.
  int connectRaceMs = 125;
  // The scene this client draws for (the hash describeScene returned, whose package it loaded): a
  // volume description that names another scene is refused and the client stops (fatal), for
  // what it would draw is not what the probes were traced in. Empty: any scene.
  std::optional<SceneHash> scene;
  // The most probes a volume description may hold: one of more is refused before any memory is set
  // aside for it, and the client stops (fatal). At most kMaxProbes (the protocol's limit).
  uint64_t maxProbes = kMaxProbes;
  // fetchScene: a server that sends no piece of the scene for this long is given up on (the next
  // server, or an error), so a stalled transfer cannot hold a viewer forever.
  int sceneStallMs = 15000;
};

// What a client refused from its servers, one entry per reason (in the order first seen).
struct Refusal {
  std::string reason;  // printable (wire text escaped)
  uint32_t count = 0;
};

struct VolumeSnapshot {
  ProbeVolume volume;           // the last good volume (decodedFrom: the stream's representation;
                                // offsets, areaLights and scene: the description's, scene.time the
                                // newest frame's)
  StreamLayout layout;          // the stream's grid, brick edge and representation
  uint32_t framesApplied = 0;
  uint64_t newestServerTimeUs = 0;
  // The scene state of the newest frame applied (hasState false before the first, or from a
  // server that sent none).
  bus::SceneState state;
  bool hasState = false;
  // The server's wall clock is this client's minus clockOffsetUs (estimated from the frames: the
  // smallest receive − send time of the most recent 64, so one-way delay included).
  int64_t clockOffsetUs = 0;
};

// The scene time the server's clock stands at when this client's wall clock reads `localUs`
// (µs since 1970): the newest state extrapolated at its rate (its time when it holds still).
double serverSceneTime(const VolumeSnapshot& snapshot, uint64_t localUs);

// A viewer's display clock, locked to the server's scene clock. Each frame it is asked for the
// scene time to draw at: the server's (serverSceneTime), held where it would step back by less than
// one second of playback (so small corrections never run the picture backwards) and followed at once
// when it jumps ahead or is more than one second behind (a stream that restarted or rewound).
// While the stream stalls, the estimate runs on at the last rate: direct light keeps moving, the
// probes keep their light and grow older (probeAge).
class DisplayClock {
 public:
  double at(const VolumeSnapshot& snapshot, uint64_t localUs);
  // Scene seconds between the time last drawn and the time the newest probes were traced at.
  double probeAge() const { return age_; }
  double last() const { return last_; }

 private:
  bool started_ = false;
  double last_ = 0.0, age_ = 0.0;
};

// Microseconds since 1970 on this machine's wall clock.
uint64_t wallClockUs();

// The scene a server's stream names (GetVolume from the config's servers in turn; an unknown
// stamp when it names none). False with `error` when no server answers or the description is bad.
bool describeScene(const ClientConfig& config, SceneStamp& out, std::string& error);

struct SceneFetch {
  uint64_t bytes = 0;     // file bytes received (0 when the cache held the package)
  double ms = 0.0;
  bool fromCache = false;
};
// The scene package of `scene` (a description's stamp): from `cache` when it holds it whole,
// else fetched with GetScene from the config's servers in turn, checked (every file's size and
// SHA-256) and stored in the cache. Refuses a package of more than maxBytes before fetching it.
// False with `error` naming the reason (refused, not found, too large, a file that does not match).
bool fetchScene(const ClientConfig& config, const SceneStamp& scene, const std::filesystem::path& cache,
                uint64_t maxBytes, ScenePackage& out, SceneFetch& fetch, std::string& error);

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
  // The link as the server estimates it (linkPacing, where the server paces; 0 otherwise).
  uint64_t serverLinkRate = 0;       // delivery rate, bytes per second
  uint32_t serverLinkMinRttUs = 0;   // frame → ack round trip, windowed minimum
  uint64_t serverLinkWindow = 0;     // unacknowledged bytes it allows on the way
  uint64_t serverLinkInFlight = 0;   // unacknowledged bytes on the way
  uint32_t serverLinkWaits = 0;      // frames that waited for the window
  uint32_t silences = 0;             // calls cut for silence (ClientConfig::silenceMs), or unanswered
                                     // after connecting began (reconnectSilenceMs)
  uint64_t connectAttempts = 0;     // connections begun (several overlap: ClientConfig::connectRaceMs)
  uint32_t descriptionsResumed = 0;  // descriptions that left out the offsets and manifest held
  // Every description and frame refused, and every failed call, counted by reason (at most 32
  // reasons; later ones count under the last).
  std::vector<Refusal> refusals;
};

// The refusals as lines for a user: "REASON" or "REASON (N times)", one per reason.
std::vector<std::string> refusalLines(const ClientStats& stats);

// One frame the client applied (ProbeClient::appliedFrames).
struct AppliedFrame {
  uint64_t appliedUs = 0;  // wall clock when it was applied, µs since 1970
  uint32_t latencyUs = 0;  // from the publish of its newest lighting (server clock) to then
  uint32_t bytes = 0;      // payload
  uint32_t keyframes = 0;  // brick sections that were keyframes
  uint32_t deltas = 0;
  uint32_t bricksHeld = 0; // bricks of the volume held after it (all of them: a usable volume)
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
  // The most recent 4096 frames applied, oldest first.
  std::vector<AppliedFrame> appliedFrames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::service
