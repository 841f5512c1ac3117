#include "load_client.h"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "probecast.grpc.pb.h"
#include "probecast/codec/stream.h"
#include "wire_convert.h"

namespace probecast::bench {

namespace pb = probecast::v1;

uint64_t volumeHash(const float* probes, const uint8_t* active, size_t count) {
  uint64_t h = 0xcbf29ce484222325ull;
  const auto mix = [&h](const uint8_t* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  };
  mix(reinterpret_cast<const uint8_t*>(probes), count * kProbeFloats * sizeof(float));
  mix(active, count);
  return h;
}

namespace {

uint64_t systemNowUs() {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// Figures shared by all streams of a client; the histograms in a few shards so that streams
// answered on different gRPC threads rarely wait for each other.
struct Tally {
  static constexpr size_t kShards = 8;
  std::atomic<uint64_t> frames{0}, bytes{0}, sequenceErrors{0}, crcErrors{0}, decodeErrors{0}, streamErrors{0};
  struct Shard {
    std::mutex mutex;
    service::LatencyHistogram latency;
  };
  Shard shards[kShards];
  std::mutex errorMutex;
  std::string lastError;
  // Streams that have their volume description / have ended.
  std::mutex stateMutex;
  std::condition_variable stateChanged;
  uint32_t connected = 0, ended = 0;

  void error(const std::string& why) {
    std::lock_guard<std::mutex> lock(errorMutex);
    lastError = why;
  }
};

class Subscriber : public grpc::ClientBidiReactor<pb::ClientMessage, pb::ServerMessage> {
 public:
  Subscriber(Tally& tally, uint32_t index, bool decodes, uint32_t ackIntervalMs, bool linkPacing)
      : tally_(tally), index_(index), decodes_(decodes), ackIntervalUs_(uint64_t{ackIntervalMs} * 1000),
        linkPacing_(linkPacing) {}

  void start(pb::ProbeStream::Stub& stub, const std::string& token, uint64_t budget, const std::optional<View>& view) {
    if (!token.empty()) ctx_.AddMetadata("authorization", "Bearer " + token);
    pb::Hello* h = hello_.mutable_hello();
    h->set_protocol_version(service::kProtocolVersion);
    h->set_budget_bytes_per_second(budget);
    h->set_client_name("probecast-load-" + std::to_string(index_));
    h->set_acks_every_frame(linkPacing_);
    if (view) service::viewsToWire({*view}, *views_.mutable_views());
    haveViews_ = view.has_value();
    stub.async()->Subscribe(&ctx_, this);
    writing_ = true;
    StartWrite(&hello_);
    StartRead(&in_);
    StartCall();
  }

  void cancel() {
    stopping_ = true;
    ctx_.TryCancel();
  }

  void OnReadDone(bool ok) override {
    if (!ok) return;  // the stream is over; OnDone follows with its status
    if (in_.has_frame()) {
      if (!onFrame(in_.frame())) {
        ctx_.TryCancel();
        return;
      }
    } else if (in_.has_volume()) {
      onVolume(in_.volume());
    }
    StartRead(&in_);
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(writeMutex_);
    writing_ = false;
    if (ok) pumpLocked();
  }

  void OnDone(const grpc::Status& status) override {
    if (!status.ok() && !stopping_) {
      tally_.streamErrors++;
      tally_.error("stream " + std::to_string(index_) + " ended: " + status.error_message());
    }
    std::lock_guard<std::mutex> lock(tally_.stateMutex);
    tally_.ended++;
    tally_.stateChanged.notify_all();
  }

  bool decodes() const { return decodes_; }
  // The decoder's volume hash; 0 before the volume description.
  uint64_t heldHash() {
    std::lock_guard<std::mutex> lock(decoderMutex_);
    if (!decoder_) return 0;
    return volumeHash(decoder_->probes(), decoder_->activeMask(), probeCount(decoder_->layout()));
  }

 private:
  void onVolume(const pb::VolumeDescription& v) {
    StreamLayout layout;
    GridBounds bounds;
    std::string why;
    std::vector<float> offsets;  // where the probes are and what they leave out: not needed to count bytes
    AreaLightRule areaLights;
    SceneStamp scene;
    if (!service::volumeFromWire(v, layout, bounds, offsets, areaLights, scene, why)) {
      tally_.error("bad volume description: " + why);
      return;
    }
    if (decodes_) {
      std::lock_guard<std::mutex> lock(decoderMutex_);
      decoder_ = std::make_unique<StreamDecoder>(layout);
    }
    std::lock_guard<std::mutex> lock(tally_.stateMutex);
    tally_.connected++;
    tally_.stateChanged.notify_all();
  }

  // False when the stream cannot go on (a frame the decoder refused leaves it out of step).
  bool onFrame(const pb::Frame& f) {
    const uint64_t now = systemNowUs();
    const auto* data = reinterpret_cast<const uint8_t*>(f.payload().data());
    const size_t size = f.payload().size();
    FrameHeader header;
    const CodecStatus st = verifyFrame(data, size, &header);
    if (st != CodecStatus::Ok) {
      tally_.crcErrors++;
      tally_.error(std::string("frame failed its container check: ") + codecStatusName(st));
    }
    if (f.sequence() != lastSequence_ + 1 || (st == CodecStatus::Ok && header.frameSequence != f.sequence())) {
      tally_.sequenceErrors++;
      tally_.error("frame " + std::to_string(f.sequence()) + " after " + std::to_string(lastSequence_));
    }
    lastSequence_ = f.sequence();
    tally_.frames++;
    tally_.bytes += size;
    {
      Tally::Shard& shard = tally_.shards[index_ % Tally::kShards];
      std::lock_guard<std::mutex> lock(shard.mutex);
      shard.latency.record(now - std::min(now, f.server_time_us()));
    }
    if (decodes_) {
      std::lock_guard<std::mutex> lock(decoderMutex_);
      const CodecStatus d = decoder_ ? decoder_->apply(data, size) : CodecStatus::LayoutMismatch;
      if (d != CodecStatus::Ok) {
        tally_.decodeErrors++;
        tally_.error(std::string("sampled subscriber could not decode a frame: ") + codecStatusName(d));
        return false;
      }
    }
    std::lock_guard<std::mutex> lock(writeMutex_);
    ackPending_ = f.sequence();  // acks are cumulative: the newest one says it all
    pumpLocked();
    return true;
  }

  // One write in flight: hello, then the view set, then the newest ack whenever one is due (the
  // first at once, then at most one per ackIntervalMs; every one when paced).
  void pumpLocked() {
    if (writing_) return;
    if (haveViews_) {
      haveViews_ = false;
      writing_ = true;
      StartWrite(&views_);
    } else if (ackPending_ != 0 && (lastAckUs_ == 0 || linkPacing_ || systemNowUs() - lastAckUs_ >= ackIntervalUs_)) {
      lastAckUs_ = systemNowUs();
      ack_.mutable_ack()->set_frame_sequence(ackPending_);
      ackPending_ = 0;
      writing_ = true;
      StartWrite(&ack_);
    }
  }

  Tally& tally_;
  const uint32_t index_;
  const bool decodes_;
  const uint64_t ackIntervalUs_;
  const bool linkPacing_;
  std::atomic<bool> stopping_{false};
  grpc::ClientContext ctx_;
  pb::ClientMessage hello_, views_, ack_;
  pb::ServerMessage in_;
  uint32_t lastSequence_ = 0;  // touched by OnReadDone only (one read at a time)
  std::mutex writeMutex_;      // the write state below
  bool writing_ = false, haveViews_ = false;
  uint32_t ackPending_ = 0;
  uint64_t lastAckUs_ = 0;  // 0: none yet
  std::mutex decoderMutex_;
  std::unique_ptr<StreamDecoder> decoder_;
};

}  // namespace

struct LoadClient::Impl {
  LoadClientConfig config;
  Tally tally;
  std::vector<std::unique_ptr<pb::ProbeStream::Stub>> stubs;  // address-major, channelsPerAddress each
  std::vector<std::unique_ptr<Subscriber>> subscribers;
  bool started = false, stopped = false;
};

LoadClient::LoadClient(const LoadClientConfig& config) : impl_(std::make_unique<Impl>()) {
  if (config.addresses.empty()) throw std::invalid_argument("a load client needs at least one server address");
  if (config.subscribers == 0) throw std::invalid_argument("a load client needs at least one subscriber");
  impl_->config = config;
  impl_->config.channelsPerAddress = std::max(1u, config.channelsPerAddress);
  impl_->config.sampleEvery = std::max(1u, config.sampleEvery);
}

LoadClient::~LoadClient() { stop(); }

void LoadClient::start() {
  Impl& s = *impl_;
  if (s.started) return;
  s.started = true;
  const LoadClientConfig& c = s.config;
  for (const std::string& address : c.addresses)
    for (uint32_t k = 0; k < c.channelsPerAddress; ++k) {
      grpc::ChannelArguments args;
      args.SetMaxReceiveMessageSize(256 << 20);
      // Channels of their own, not one shared connection: a distinct argument and a local pool.
      args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
      args.SetInt("probecast.load_channel", static_cast<int>(k));
      s.stubs.push_back(
          pb::ProbeStream::NewStub(grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args)));
    }
  const size_t addresses = c.addresses.size();
  for (uint32_t i = 0; i < c.subscribers; ++i) {
    const uint32_t index = c.firstIndex + i;
    s.subscribers.push_back(std::make_unique<Subscriber>(s.tally, index, index % c.sampleEvery == 0, c.ackIntervalMs,
                                                        c.linkPacing));
    const size_t a = index % addresses, channel = (index / addresses) % c.channelsPerAddress;
    std::optional<View> view;
    if (c.view) view = c.view(index);
    s.subscribers.back()->start(*s.stubs[a * c.channelsPerAddress + channel], c.token, c.budgetBytesPerSecond, view);
  }
}

uint32_t LoadClient::waitConnected(std::chrono::milliseconds timeout) {
  Tally& t = impl_->tally;
  std::unique_lock<std::mutex> lock(t.stateMutex);
  const uint32_t n = static_cast<uint32_t>(impl_->subscribers.size());
  t.stateChanged.wait_for(lock, timeout, [&] { return t.connected >= n || t.ended >= n; });
  return t.connected;
}

LoadFigures LoadClient::take() {
  Tally& t = impl_->tally;
  LoadFigures f;
  f.frames = t.frames.exchange(0);
  f.bytes = t.bytes.exchange(0);
  f.sequenceErrors = t.sequenceErrors.exchange(0);
  f.crcErrors = t.crcErrors.exchange(0);
  f.decodeErrors = t.decodeErrors.exchange(0);
  f.streamErrors = t.streamErrors.exchange(0);
  for (Tally::Shard& shard : t.shards) {
    std::lock_guard<std::mutex> lock(shard.mutex);
    f.latency.merge(shard.latency);
    shard.latency.clear();
  }
  std::lock_guard<std::mutex> lock(t.errorMutex);
  f.lastError = t.lastError;
  return f;
}

SampleCheck LoadClient::checkSamples(uint64_t expected, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  SampleCheck check;
  for (;;) {
    check = {};
    for (auto& sub : impl_->subscribers)
      if (sub->decodes()) {
        ++check.sampled;
        check.identical += sub->heldHash() == expected ? 1 : 0;
      }
    if (check.identical == check.sampled || std::chrono::steady_clock::now() >= deadline) return check;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void LoadClient::stop() {
  Impl& s = *impl_;
  if (!s.started || s.stopped) return;
  s.stopped = true;
  for (auto& sub : s.subscribers) sub->cancel();
  Tally& t = s.tally;
  std::unique_lock<std::mutex> lock(t.stateMutex);
  t.stateChanged.wait(lock, [&] { return t.ended >= s.subscribers.size(); });
}

}  // namespace probecast::bench
