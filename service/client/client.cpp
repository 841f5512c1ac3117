// The subscriber side: one worker thread per client holding a synchronous bidirectional stream.
#include "probecast/service/client.h"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <condition_variable>
#include <map>
#include <cstdlib>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "probecast.grpc.pb.h"
#include "stream_checks.h"
#include "wire_convert.h"

namespace probecast::service {

namespace pb = probecast::v1;
using Stream = grpc::ClientReaderWriter<pb::ClientMessage, pb::ServerMessage>;

namespace {

// connectTimeoutMs (0: gRPC's 20 s): how long the connection may take to come up before the channel
// gives it up.
std::shared_ptr<grpc::Channel> makeChannel(const ClientConfig& config, const std::string& address,
                                           int connectTimeoutMs = 0) {
  grpc::ChannelArguments args;
  if (connectTimeoutMs > 0) args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, connectTimeoutMs);
  args.SetMaxReceiveMessageSize(256 << 20);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, config.keepaliveMs);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, config.keepaliveTimeoutMs);
  args.SetInt(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  args.SetInt(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);  // a still volume sends nothing for long
  // Every subscription gets a connection of its own: after a cut (ClientConfig::silenceMs) a new
  // channel must not reuse the stalled connection from gRPC's shared pool.
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  std::shared_ptr<grpc::ChannelCredentials> creds;
  if (config.tls) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = config.rootCertPem;
    creds = grpc::SslCredentials(options);
    if (!config.tlsServerName.empty()) args.SetSslTargetNameOverride(config.tlsServerName);
  } else {
    creds = grpc::InsecureChannelCredentials();
  }
  return grpc::CreateCustomChannel(address, creds, args);
}

// The servers to try, in order.
std::vector<std::string> serversOf(const ClientConfig& config) {
  return config.addresses.empty() ? std::vector<std::string>{config.address} : config.addresses;
}

// A call's context with the config's bearer token.
void authorize(const ClientConfig& config, grpc::ClientContext& ctx) {
  if (!config.token.empty()) ctx.AddMetadata("authorization", "Bearer " + config.token);
}

// Cancels a call that makes no progress for `stallMs`: a server that stops sending mid-transfer
// cannot hold the caller. progress() after every message; stalled() tells whether it cancelled.
class StallGuard {
 public:
  StallGuard(grpc::ClientContext& ctx, int stallMs) : thread_([this, &ctx, stallMs] { watch(ctx, stallMs); }) {}
  ~StallGuard() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  StallGuard(const StallGuard&) = delete;
  StallGuard& operator=(const StallGuard&) = delete;
  void progress() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++progress_;
    wake_.notify_all();
  }
  bool stalled() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stalled_;
  }

 private:
  void watch(grpc::ClientContext& ctx, int stallMs) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!done_) {
      const uint64_t seen = progress_;
      if (!wake_.wait_for(lock, std::chrono::milliseconds(stallMs), [&] { return done_ || progress_ != seen; })) {
        stalled_ = true;
        ctx.TryCancel();
        return;
      }
    }
  }
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  uint64_t progress_ = 0;
  bool done_ = false, stalled_ = false;
  std::thread thread_;  // last: it starts once the members above are made
};

// Connection attempts to one server that overlap (ClientConfig::connectRaceMs). A channel makes
// progress only while someone polls it: a call, or here a watch of its state on the queue.
class ConnectRace {
 public:
  ConnectRace() = default;
  ConnectRace(const ConnectRace&) = delete;
  ConnectRace& operator=(const ConnectRace&) = delete;
  ~ConnectRace() {  // every watch ends by its deadline
    queue_.Shutdown();
    void* tag;
    bool ok;
    while (queue_.Next(&tag, &ok)) {
    }
  }
  // Begins connecting `channel`; the oldest attempt is dropped past kConnectRaceAttempts.
  void begin(std::shared_ptr<grpc::Channel> channel) {
    if (attempts_.size() == static_cast<size_t>(kConnectRaceAttempts)) attempts_.erase(attempts_.begin());
    const uintptr_t id = ++serial_;
    channel->GetState(true);
    watch(id, *channel, GRPC_CHANNEL_IDLE);
    attempts_.emplace(id, std::move(channel));
  }
  // Drops every attempt but `winner` (their watches end within their deadline).
  void keepOnly(const std::shared_ptr<grpc::Channel>& winner) {
    std::erase_if(attempts_, [&](const auto& a) { return a.second != winner; });
  }
  // An attempt that came up or failed before `until`, or null.
  std::shared_ptr<grpc::Channel> wait(std::chrono::steady_clock::time_point until) {
    void* tag;
    bool ok;
    const auto deadline = std::chrono::system_clock::now() + (until - std::chrono::steady_clock::now());
    while (queue_.AsyncNext(&tag, &ok, deadline) == grpc::CompletionQueue::GOT_EVENT) {
      const auto it = attempts_.find(reinterpret_cast<uintptr_t>(tag));
      if (it == attempts_.end()) continue;  // dropped; its watch has ended
      const grpc_connectivity_state s = it->second->GetState(false);
      if (s == GRPC_CHANNEL_READY || s == GRPC_CHANNEL_TRANSIENT_FAILURE || s == GRPC_CHANNEL_SHUTDOWN) return it->second;
      watch(it->first, *it->second, s);
    }
    return nullptr;
  }

 private:
  // The watch's deadline bounds how long a dropped attempt lives on and how long the end waits.
  void watch(uintptr_t id, grpc::Channel& channel, grpc_connectivity_state seen) {
    channel.NotifyOnStateChange(seen, std::chrono::system_clock::now() + std::chrono::milliseconds(100), &queue_,
                                reinterpret_cast<void*>(id));
  }
  grpc::CompletionQueue queue_;
  std::map<uintptr_t, std::shared_ptr<grpc::Channel>> attempts_;  // by serial, oldest first
  uintptr_t serial_ = 0;
};

}  // namespace

std::vector<std::string> refusalLines(const ClientStats& stats) {
  std::vector<std::string> lines;
  for (const Refusal& r : stats.refusals)
    lines.push_back(r.count == 1 ? r.reason : r.reason + " (" + std::to_string(r.count) + " times)");
  return lines;
}

struct ProbeClient::Impl {
  ClientConfig config;
  std::thread worker;
  std::atomic<bool> stopping{false};
  mutable std::mutex mutex;  // everything below
  std::condition_variable wakeup;
  std::unique_ptr<StreamDecoder> decoder;
  StreamLayout layout;
  GridBounds bounds;
  std::vector<float> offsets;  // the description's probe offsets, metres
  AreaLightRule areaLights;    // the description's client area light rule
  SceneStamp scene;            // the description's scene (time: of the newest state)
  bus::SceneState state;       // of the newest frame
  bool hasState = false;
  std::vector<int64_t> offsets64;  // receive − send of the most recent 64 frames, µs
  size_t offsetNext = 0;
  uint64_t epoch = 0;
  // The description's offsets and manifest as they came (a resume names them by their digest, and
  // a server that has them unchanged leaves them out: VolumeDescription.held_parts).
  std::string heldOffsets, heldManifest;
  bool heldParts = false;  // the two above belong to `epoch`'s description
  uint64_t newestServerTimeUs = 0;
  std::vector<AppliedFrame> applied;  // ring of the most recent 4096
  size_t appliedNext = 0;
  std::vector<View> views;
  ClientStats stats;
  grpc::ClientContext* context = nullptr;
  Stream* stream = nullptr;
  // The silence watchdog (ClientConfig::silenceMs): when the call began, its last message, the
  // server's heartbeat promise (kept across calls), and whether the watchdog cut the call.
  std::thread watchdog;
  std::chrono::steady_clock::time_point callStarted, lastMessage;
  uint32_t heartbeatMs = 0;
  bool silenced = false;
  // A call not yet answered: its channel (READY once TCP, TLS and HTTP/2 are up, which restarts
  // its allowance), and how many calls in a row were cut unanswered (every other one gets twice
  // the allowance, so that a link slower than reconnectSilenceMs still gets through).
  std::shared_ptr<grpc::Channel> callChannel;
  std::chrono::steady_clock::time_point readyAt;
  bool callReady = false;
  uint32_t unanswered = 0;
  bool finishing = false, finishCut = false;  // in Finish since finishStarted; cut by the watchdog
  std::chrono::steady_clock::time_point finishStarted;

  void watch() {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping) {
      wakeup.wait_for(lock, std::chrono::milliseconds(100), [&] { return stopping.load(); });
      if (stopping || !context) continue;
      const auto now = std::chrono::steady_clock::now();
      // A stream whose reads ended without its end (a message that did not parse leaves the call
      // open): Finish would wait for the server, so the call is cut.
      if (finishing && !finishCut && now - finishStarted > std::chrono::milliseconds(1000)) {
        finishCut = true;
        context->TryCancel();
        continue;
      }
      if (heartbeatMs == 0 || silenced || finishing) continue;
      const bool heard = lastMessage > callStarted;
      if (!heard && !callReady && callChannel && callChannel->GetState(false) == GRPC_CHANNEL_READY) {
        callReady = true;
        readyAt = now;
      }
      const int limit = heard ? config.silenceMs : config.reconnectSilenceMs * static_cast<int>(1 + unanswered % 2);
      const auto since = heard ? lastMessage : callReady ? readyAt : callStarted;
      if (limit <= 0 || now - since < std::chrono::milliseconds(limit)) continue;
      silenced = true;
      stats.silences += 1;
      context->TryCancel();
    }
  }
  std::mutex writeMutex;  // one writer at a time on the stream

  bool write(const pb::ClientMessage& m) {
    std::lock_guard<std::mutex> w(writeMutex);
    Stream* s;
    {
      std::lock_guard<std::mutex> lock(mutex);
      s = stream;
    }
    return s && s->Write(m);
  }

  std::shared_ptr<grpc::Channel> channel(const std::string& address) const { return makeChannel(config, address); }

  // After a cut for silence: a channel to `address` whose connection is up (READY), or one that
  // failed to connect (a call on it fails at once, as it would have), by overlapping attempts in
  // `race` (ClientConfig::connectRaceMs), the others dropped; null once stopping or when none came
  // up within `allowanceMs`.
  std::shared_ptr<grpc::Channel> connect(ConnectRace& race, const std::string& address, int allowanceMs) {
    using Clock = std::chrono::steady_clock;
    const auto end = Clock::now() + std::chrono::milliseconds(allowanceMs);
    int interval = config.connectRaceMs;
    uint32_t begun = 0;
    auto next = Clock::now();
    while (!stopping && Clock::now() < end) {
      if (Clock::now() >= next) {
        // An attempt lives no longer than the race (and a second), dropped or not.
        race.begin(makeChannel(config, address, allowanceMs + 1000));
        if (++begun % (2 * kConnectRaceAttempts) == 0) interval = std::min(interval * 2, config.connectRaceMs * 4);
        next = Clock::now() + std::chrono::milliseconds(interval);
        std::lock_guard<std::mutex> lock(mutex);
        stats.connectAttempts += 1;
      }
      // Short waits, so that stop() is heard.
      std::shared_ptr<grpc::Channel> up = race.wait(std::min({next, end, Clock::now() + std::chrono::milliseconds(50)}));
      if (up) return race.keepOnly(up), up;
    }
    return nullptr;
  }

  // Counts `reason` (mutex held) and keeps it as the last error, escaped for printing.
  void refuse(const std::string& reason) {
    stats.lastError = printableText(reason);
    for (Refusal& r : stats.refusals)
      if (r.reason == stats.lastError) return void(r.count += 1);
    if (stats.refusals.size() < 32) stats.refusals.push_back({stats.lastError, 1});
    else stats.refusals.back().count += 1;
  }

  // A description this client will never use (another scene than the one it draws, a volume
  // beyond its limit): it stops (fatal) instead of asking again.
  bool refuseForGood(const std::string& reason) {
    refuse(reason);
    stats.fatal = true;
    return false;
  }

  // False for a description the client cannot use: the connection is dropped and retried later
  // (or, refuseForGood, never).
  bool onVolume(const pb::VolumeDescription& sent, const std::string& address) {
    Description d;
    std::string why;
    std::lock_guard<std::mutex> lock(mutex);
    pb::VolumeDescription whole;
    const bool resumed = sent.held_parts();
    if (resumed) {
      // Only the epoch whose parts we hold, asked for in our Hello; else the next Hello asks afresh.
      if (!decoder || !heldParts || sent.stream_epoch() != epoch) {
        heldParts = false;
        return refuse("a resumed description leaves out probe offsets and a manifest of another epoch: asking afresh"), false;
      }
      whole = sent;
      whole.set_probe_offsets(heldOffsets);
      whole.set_scene_manifest(heldManifest);
      whole.clear_held_parts();
    }
    const pb::VolumeDescription& v = resumed ? whole : sent;
    const Verdict verdict = checkDescription(v, config, d, why);
    if (verdict != Verdict::Accept && resumed) heldParts = false;  // the next Hello asks for all of it
    switch (verdict) {
      case Verdict::Accept: break;
      case Verdict::Retry: return refuse(why), false;
      case Verdict::ForGood: return refuseForGood(why);
    }
    const StreamLayout& l = d.layout;
    const AreaLightRule& r = d.areaLights;
    SceneStamp& sc = d.scene;
    const bool same = decoder && l.grid[0] == layout.grid[0] && l.grid[1] == layout.grid[1] &&
                      l.grid[2] == layout.grid[2] && l.brickDim == layout.brickDim && l.repr == layout.repr;
    if (!same || v.stream_epoch() != epoch || !(r == areaLights) || sc.hash != scene.hash) {  // nothing held is valid
      decoder = std::make_unique<StreamDecoder>(l);
      decoder->setZh3PerPixel(config.zh3PerPixel);
    }
    layout = l;
    bounds = d.bounds;
    offsets = std::move(d.offsets);
    areaLights = r;
    if (sc.hash != scene.hash) hasState = false;
    scene = std::move(sc);
    epoch = v.stream_epoch();
    heldOffsets = v.probe_offsets();
    heldManifest = v.scene_manifest();
    heldParts = true;
    if (resumed) stats.descriptionsResumed += 1;
    stats.connected = true;
    stats.connects += 1;
    stats.address = address;
    return true;
  }

  // Returns false when the connection should be dropped (the server and we disagree on state).
  bool onFrame(const pb::Frame& f) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!decoder) return refuse("frame before volume description"), false;
    bus::SceneState frameState;
    std::string why;
    if (!checkFrame(f, frameState, why)) {
      stats.framesRejected += 1;
      refuse(why);
      return false;
    }
    const auto* data = reinterpret_cast<const uint8_t*>(f.payload().data());
    const CodecStatus st = decoder->apply(data, f.payload().size());
    if (st != CodecStatus::Ok) {
      stats.framesRejected += 1;
      refuse(std::string("frame rejected: ") + codecStatusName(st));
      return st != CodecStatus::BaseVersionMismatch;  // resubscribe to tell the server what we hold
    }
    stats.framesApplied += 1;
    stats.bytesReceived += f.payload().size();
    stats.keyframesReceived += f.keyframes();
    stats.deltasReceived += f.deltas();
    const uint64_t now = wallClockUs();
    if (f.has_scene_state()) {
      state = std::move(frameState);
      hasState = true;
      const int64_t sample = static_cast<int64_t>(now) - static_cast<int64_t>(f.sent_us());
      if (offsets64.size() < 64) offsets64.push_back(sample);
      else offsets64[offsetNext++ % 64] = sample;
    }
    const uint32_t latency = static_cast<uint32_t>(std::min<uint64_t>(now - std::min(now, f.server_time_us()), UINT32_MAX));
    uint32_t held = 0;
    for (uint32_t b = 0; b < brickCount(layout); ++b) held += decoder->brickVersion(b) != 0 ? 1 : 0;
    const AppliedFrame record{now, latency, static_cast<uint32_t>(f.payload().size()), f.keyframes(), f.deltas(), held};
    if (applied.size() < 4096) applied.push_back(record);
    else applied[appliedNext++ % 4096] = record;
    newestServerTimeUs = std::max(newestServerTimeUs, f.server_time_us());
    return true;
  }

  pb::ClientMessage hello() {
    pb::ClientMessage m;
    pb::Hello* h = m.mutable_hello();
    h->set_protocol_version(kProtocolVersion);
    h->set_budget_bytes_per_second(config.budgetBytesPerSecond);
    h->set_client_name(config.name);
    h->set_acks_every_frame(config.linkPacing);
    if (config.representation) h->set_representation(static_cast<pb::Representation>(*config.representation));
    std::lock_guard<std::mutex> lock(mutex);
    if (decoder) {
      h->set_stream_epoch(epoch);
      if (heldParts) h->set_held_description(descriptionDigest(heldOffsets, heldManifest));
      for (uint32_t b = 0; b < brickCount(layout); ++b)
        if (decoder->brickVersion(b) != 0) {
          pb::BrickVersion* v = h->add_held();
          v->set_brick(b);
          v->set_version(decoder->brickVersion(b));
        }
    }
    return m;
  }

  void run() {
    const std::vector<std::string> servers = serversOf(config);
    size_t at = 0;
    size_t failedInTurn = 0;  // servers tried since the last one that answered
    int backoff = config.reconnectMinMs;
    bool suspect = false;  // the last call was cut for silence
    while (!stopping) {
      ConnectRace race;  // its winner's watch ends with the call
      const bool racing = suspect && config.connectRaceMs > 0;
      const int allowance = config.reconnectSilenceMs * static_cast<int>(1 + unanswered % 2);
      const std::shared_ptr<grpc::Channel> ch = racing ? connect(race, servers[at], allowance) : channel(servers[at]);
      if (stopping) return;
      if (!ch) {  // no attempt came up: as a call unanswered, on the next server if there are several
        std::lock_guard<std::mutex> lock(mutex);
        stats.silences += 1;
        unanswered += 1;
        refuse(servers[at] + ": no answer within " + std::to_string(allowance) + " ms of connecting: connecting afresh");
        if (servers.size() > 1) at = (at + 1) % servers.size();
        continue;
      }
      suspect = false;
      grpc::ClientContext ctx;
      authorize(config, ctx);
      std::unique_ptr<pb::ProbeStream::Stub> stub = pb::ProbeStream::NewStub(ch);
      {
        // The watchdog may cut the call from here on: opening it on a channel not yet connected
        // blocks while the connection is made, which through a link outage takes until TCP gives
        // up (seconds), not one attempt.
        std::lock_guard<std::mutex> lock(mutex);
        context = &ctx;
        stream = nullptr;
        callStarted = std::chrono::steady_clock::now();
        silenced = false;
        callChannel = ch;
        callReady = false;
        if (stopping) ctx.TryCancel();  // stop() came before the context was there to cancel
      }
      std::unique_ptr<Stream> rw = stub->Subscribe(&ctx);
      {
        std::lock_guard<std::mutex> lock(mutex);
        stream = rw.get();
      }
      if (stopping) ctx.TryCancel();
      write(hello());
      {
        pb::ClientMessage vm;
        {
          std::lock_guard<std::mutex> lock(mutex);
          viewsToWire(views, *vm.mutable_views());
        }
        write(vm);
      }
      pb::ServerMessage msg;
      bool gotVolume = false;
      bool dropped = false;  // by us, for a reason already in lastError
      bool acked = false;    // on this connection
      std::chrono::steady_clock::time_point lastAck;
      while (rw->Read(&msg)) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          lastMessage = std::chrono::steady_clock::now();
        }
        if (msg.has_volume()) {
          if (!onVolume(msg.volume(), servers[at])) {
            dropped = true;
            ctx.TryCancel();
            break;
          }
          gotVolume = true;
          failedInTurn = 0;
          backoff = config.reconnectMinMs;
        } else if (msg.has_stats()) {
          std::lock_guard<std::mutex> lock(mutex);
          stats.statsReceived += 1;
          stats.serverBytesSent = msg.stats().bytes_sent();
          stats.serverBricksBehind = msg.stats().bricks_behind();
          stats.serverFramesAcked = msg.stats().frames_acked();
          stats.serverAckRttUs = msg.stats().ack_rtt_us();
          stats.serverLinkRate = msg.stats().link_rate();
          stats.serverLinkMinRttUs = msg.stats().link_min_rtt_us();
          stats.serverLinkWindow = msg.stats().link_window();
          stats.serverLinkInFlight = msg.stats().link_in_flight();
          stats.serverLinkWaits = msg.stats().link_waits();
          heartbeatMs = msg.stats().heartbeat_ms();
        } else if (msg.has_frame()) {
          if (!onFrame(msg.frame())) {
            dropped = true;
            ctx.TryCancel();
            break;
          }
          const auto now = std::chrono::steady_clock::now();
          // A paced stream's acks are its link's measurement: every frame is acked at once.
          if (!acked || config.linkPacing ||
              now - lastAck >= std::chrono::milliseconds(config.ackIntervalMs)) {
            pb::ClientMessage ack;
            ack.mutable_ack()->set_frame_sequence(msg.frame().sequence());
            write(ack);
            acked = true;
            lastAck = now;
          }
        }
      }
      {
        std::lock_guard<std::mutex> w(writeMutex);  // no writer may hold the stream past this point
        std::lock_guard<std::mutex> lock(mutex);
        stream = nullptr;
        finishing = true;
        finishCut = false;
        finishStarted = std::chrono::steady_clock::now();
      }
      const grpc::Status status = rw->Finish();
      bool wasCut = false;
      {
        std::lock_guard<std::mutex> lock(mutex);
        context = nullptr;
        finishing = false;
        wasCut = finishCut;
      }
      const auto code = status.error_code();
      bool wasSilenced = false;
      {
        std::lock_guard<std::mutex> lock(mutex);
        stats.connected = false;
        const bool heard = lastMessage > callStarted;
        unanswered = heard ? 0 : unanswered + (silenced ? 1 : 0);
        callChannel.reset();
        wasSilenced = silenced;
        silenced = false;
        if (wasCut && !dropped)
          refuse(servers[at] + ": the stream broke off without an end (a message that does not parse): connecting afresh");
        else if (wasSilenced && !heard)
          refuse(servers[at] + ": no answer within " + std::to_string(config.reconnectSilenceMs * (2 - unanswered % 2)) +
                 " ms of connecting: connecting afresh");
        else if (wasSilenced)
          refuse(servers[at] + ": the connection went silent (the server promised a message every " +
                 std::to_string(heartbeatMs) + " ms): connecting afresh");
        else if (!status.ok() && !stopping && !dropped)
          refuse(servers[at] + ": " + status.error_message());
        if (stats.fatal) return;  // a description refused for good
        if (code == grpc::StatusCode::UNAUTHENTICATED || code == grpc::StatusCode::INVALID_ARGUMENT ||
            code == grpc::StatusCode::PERMISSION_DENIED) {
          stats.fatal = true;
          return;  // retrying would be refused the same way
        }
      }
      if (stopping) return;
      // ABORTED: the server's stream epoch changed (its producer restarted); subscribe there
      // again at once. Anything else (unavailable, a dead connection): the next server, at once,
      // until every one has failed in turn; then back off.
      if (code == grpc::StatusCode::ABORTED && gotVolume) continue;
      // Cut for silence (a link outage stalls TCP, whose retransmissions back off for seconds after
      // the link returns): a fresh connection at once, on the next server if there are several.
      if (wasSilenced) {
        suspect = true;
        if (servers.size() > 1) at = (at + 1) % servers.size();
        continue;
      }
      const bool moved = servers.size() > 1 && code != grpc::StatusCode::ABORTED;
      if (moved) {
        at = (at + 1) % servers.size();
        std::lock_guard<std::mutex> lock(mutex);
        stats.failovers += 1;
      }
      if (!gotVolume) ++failedInTurn;
      if (moved && failedInTurn < servers.size()) continue;
      failedInTurn = 0;
      std::unique_lock<std::mutex> lock(mutex);
      wakeup.wait_for(lock, std::chrono::milliseconds(backoff), [&] { return stopping.load(); });
      backoff = std::min(backoff * 2, config.reconnectMaxMs);
    }
  }
};

ProbeClient::ProbeClient(const ClientConfig& config) : impl_(std::make_unique<Impl>()) { impl_->config = config; }

ProbeClient::~ProbeClient() { stop(); }

void ProbeClient::start() {
  if (impl_->worker.joinable()) return;
  impl_->stopping = false;
  impl_->worker = std::thread([this] { impl_->run(); });
  impl_->watchdog = std::thread([this] { impl_->watch(); });
}

void ProbeClient::stop() {
  Impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.stopping = true;
    if (s.context) s.context->TryCancel();
  }
  s.wakeup.notify_all();
  if (s.worker.joinable()) s.worker.join();
  if (s.watchdog.joinable()) s.watchdog.join();
}

void ProbeClient::setViews(std::vector<View> views) {
  pb::ClientMessage m;
  viewsToWire(views, *m.mutable_views());
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->views = std::move(views);
  }
  impl_->write(m);
}

bool ProbeClient::snapshot(VolumeSnapshot& out) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (!impl_->decoder) return false;
  out.layout = impl_->layout;
  impl_->decoder->copyVolume(impl_->bounds, out.volume);
  out.volume.offsets = impl_->offsets;
  out.volume.areaLights = impl_->areaLights;
  out.volume.scene = impl_->scene;
  out.state = impl_->state;
  out.hasState = impl_->hasState;
  if (out.hasState) out.volume.scene.time = out.state.time;
  out.clockOffsetUs = impl_->offsets64.empty() ? 0 : *std::min_element(impl_->offsets64.begin(), impl_->offsets64.end());
  out.framesApplied = impl_->stats.framesApplied;
  out.newestServerTimeUs = impl_->newestServerTimeUs;
  return true;
}

ClientStats ProbeClient::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

std::vector<uint32_t> ProbeClient::latenciesUs() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<uint32_t> l;
  l.reserve(impl_->applied.size());
  for (const AppliedFrame& f : impl_->applied) l.push_back(f.latencyUs);
  return l;
}

std::vector<AppliedFrame> ProbeClient::appliedFrames() const {
  std::vector<AppliedFrame> frames;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    frames = impl_->applied;
  }
  std::stable_sort(frames.begin(), frames.end(),
                   [](const AppliedFrame& a, const AppliedFrame& b) { return a.appliedUs < b.appliedUs; });
  return frames;
}

void ProbeClient::dropConnection() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->context) impl_->context->TryCancel();
}

uint64_t wallClockUs() {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

double serverSceneTime(const VolumeSnapshot& s, uint64_t localUs) {
  if (!s.hasState) return s.volume.scene.time;
  const double serverUs = static_cast<double>(localUs) - static_cast<double>(s.clockOffsetUs);
  return s.state.time + s.state.rate * (serverUs - static_cast<double>(s.state.clockUs)) * 1e-6;
}

double DisplayClock::at(const VolumeSnapshot& s, uint64_t localUs) {
  const double target = serverSceneTime(s, localUs);
  const double second = std::fabs(s.hasState ? s.state.rate : 0.0);  // scene seconds per second of playback
  if (!started_ || target >= last_ || last_ - target > second || second == 0.0) last_ = target;
  started_ = true;
  age_ = last_ - (s.hasState ? s.state.time : s.volume.scene.time);
  return last_;
}

bool describeScene(const ClientConfig& config, SceneStamp& out, std::string& error) {
  const std::vector<std::string> servers = serversOf(config);
  std::string errors;
  for (const std::string& server : servers) {
    grpc::ClientContext ctx;
    authorize(config, ctx);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    pb::VolumeDescription v;
    const grpc::Status status = pb::ProbeStream::NewStub(makeChannel(config, server))->GetVolume(&ctx, {}, &v);
    if (!status.ok()) {
      errors += (errors.empty() ? "" : "; ") + server + ": " + status.error_message();
      if (status.error_code() == grpc::StatusCode::UNAUTHENTICATED) break;
      continue;
    }
    ClientConfig any = config;  // the stream as described; what is asked for comes with Subscribe
    any.representation.reset();
    any.scene.reset();
    Description d;
    std::string why;
    if (checkDescription(v, any, d, why) != Verdict::Accept) return error = printableText(server + ": " + why, 2048), false;
    out = std::move(d.scene);
    return true;
  }
  return error = printableText("no server described its stream: " + errors, 2048), false;
}

namespace {

struct SceneAttempt {
  uint64_t bytes = 0;
  std::string error;  // empty: fetched
  grpc::StatusCode code = grpc::StatusCode::OK;
  int retryMs = 0;  // > 0: the server asked to be asked again after this long
};

// One GetScene call to `server`, written into the cache as `named`; true with `out` filled.
bool fetchSceneOnce(const ClientConfig& config, const std::string& server, const SceneStamp& scene,
                    const std::filesystem::path& cache, const ScenePackage& named, ScenePackage& out, SceneAttempt& a) {
  a = {};
  grpc::ClientContext ctx;
  authorize(config, ctx);
  pb::GetSceneRequest request;
  request.set_scene_hash(reinterpret_cast<const char*>(scene.hash.data()), scene.hash.size());
  std::unique_ptr<pb::ProbeStream::Stub> stub = pb::ProbeStream::NewStub(makeChannel(config, server));
  std::unique_ptr<grpc::ClientReader<pb::SceneChunk>> reader = stub->GetScene(&ctx, request);
  PackageWriter writer(cache, named);
  pb::SceneChunk chunk;
  std::string error;
  bool ok = writer.begin(error);  // false: a local failure, the call is cancelled
  StallGuard guard(ctx, config.sceneStallMs);
  const bool answered = ok && reader->Read(&chunk);
  if (answered && chunk.manifest() != scene.manifest) ok = false, error = "it sent another manifest than its description";
  while (ok && answered && reader->Read(&chunk)) {
    guard.progress();
    ok = writer.write(chunk.path(), chunk.offset(), chunk.data(), error);
    a.bytes += chunk.data().size();
  }
  if (!ok) ctx.TryCancel();
  const grpc::Status status = reader->Finish();
  a.code = status.error_code();
  if (guard.stalled()) ok = false, error = "it sent nothing for " + std::to_string(config.sceneStallMs) + " ms";
  if (ok && answered && status.ok() && writer.finish(out, error)) return true;
  if (ok && status.ok() && !answered) error = "it sent nothing";
  a.error = ok && !status.ok() ? status.error_message() : error;
  if (a.error.empty()) a.error = "it failed without a reason";
  const auto retry = ctx.GetServerTrailingMetadata().find(kSceneRetryMetadata);
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE && retry != ctx.GetServerTrailingMetadata().end())
    a.retryMs = std::clamp(std::atoi(std::string(retry->second.data(), retry->second.size()).c_str()), 10, 5000);
  return false;
}

}  // namespace

bool fetchScene(const ClientConfig& config, const SceneStamp& scene, const std::filesystem::path& cache,
                uint64_t maxBytes, ScenePackage& out, SceneFetch& fetch, std::string& error) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsedMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  fetch = {};
  if (findCachedPackage(cache, scene.hash, out)) {
    fetch.fromCache = true;
    fetch.ms = elapsedMs();
    return true;
  }
  ScenePackage named;
  if (!parseManifest(scene.manifest, named, error) || named.hash != scene.hash)
    return error = "the scene's manifest " + (error.empty() ? "does not match its hash" : error), false;
  if (named.totalBytes() > maxBytes)
    return error = "the scene " + named.describe() + " is " + std::to_string(named.totalBytes()) +
                   " bytes, more than the " + std::to_string(maxBytes) + " this viewer accepts", false;
  if (named.files.empty()) {  // a built-in: the manifest is the whole package
    out = std::move(named);
    fetch.ms = elapsedMs();
    return true;
  }
  const std::vector<std::string> servers = serversOf(config);
  std::string errors;
  for (const std::string& server : servers) {
    // A server still getting the scene it names (an edge just started) says when to ask again.
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(config.sceneStallMs);
    SceneAttempt a;
    while (!fetchSceneOnce(config, server, scene, cache, named, out, a) && a.retryMs > 0 &&
           std::chrono::steady_clock::now() + std::chrono::milliseconds(a.retryMs) < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(a.retryMs));
    if (a.error.empty()) {
      fetch.bytes = a.bytes;
      fetch.ms = elapsedMs();
      return true;
    }
    errors += (errors.empty() ? "" : "; ") + server + ": " + a.error;
    if (a.code == grpc::StatusCode::UNAUTHENTICATED) break;
  }
  return error = printableText("cannot fetch the scene: " + errors, 2048), false;
}

}  // namespace probecast::service
