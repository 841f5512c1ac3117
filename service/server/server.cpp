// ProbeStream over gRPC's callback API: authentication, validation, one reactor per subscriber.
#include "probecast/service/server.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <grpc/slice.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include "probecast.grpc.pb.h"
#include "wire_convert.h"

namespace probecast::service {
namespace {

namespace pb = probecast::v1;

// The service reads and writes raw bytes so that it parses client messages itself: a message that
// does not parse is refused, where the generated code would end the stream as if it were closed.
using RawReactor = grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>;

// The most one held brick adds to a Hello: the field's tag and length, then brick and version as
// tagged varints of up to 5 bytes each.
constexpr size_t kHeldBrickWireBytes = 14;

// A resuming Hello lists every brick it holds, so its limit grows with the volume's bricks.
size_t helloLimit(const ServerConfig& config, const StreamLayout& layout) {
  return config.maxMessageBytes + (isValidLayout(layout) ? kHeldBrickWireBytes * brickCount(layout) : 0);
}

bool authorized(grpc::CallbackServerContext* ctx, const std::string& token, bool noAuth) {
  if (token.empty()) return noAuth;  // the constructor refuses an empty token without noAuth
  const auto& md = ctx->client_metadata();
  const auto it = md.find("authorization");
  if (it == md.end()) return false;
  const std::string got(it->second.data(), it->second.size());
  const std::string want = "Bearer " + token;
  if (got.size() != want.size()) return false;
  unsigned diff = 0;  // no early exit: the comparison takes the same time wherever it differs
  for (size_t i = 0; i < got.size(); ++i) diff |= static_cast<unsigned>(got[i] ^ want[i]);
  return diff == 0;
}

// Sends a scene package: the manifest, then every file in pieces, one write in flight.
// The unary and server-streaming calls take raw bytes, so that a request that does not parse is
// answered INVALID_ARGUMENT (gRPC's typed handlers answer UNIMPLEMENTED) with the message's name.
template <class T>
bool parseRequest(const grpc::ByteBuffer* bytes, T& out) {
  grpc::ByteBuffer copy(*bytes);
  return grpc::SerializationTraits<T>::Deserialize(&copy, &out).ok();
}

template <class T>
grpc::Status notA(const grpc::ByteBuffer* bytes) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "a request of " + std::to_string(bytes->Length()) +
                                                              " bytes is not a valid " + T::descriptor()->full_name());
}

template <class T>
grpc::ByteBuffer serialized(const T& message) {
  grpc::ByteBuffer out;
  bool own = false;
  grpc::SerializationTraits<T>::Serialize(message, &out, &own);
  return out;
}

class RefusedSceneReactor : public grpc::ServerWriteReactor<grpc::ByteBuffer> {
  void OnDone() override { delete this; }
};

class SceneReactor : public grpc::ServerWriteReactor<grpc::ByteBuffer> {
 public:
  SceneReactor(std::shared_ptr<const ScenePackage> package, size_t chunkBytes)
      : package_(std::move(package)), buffer_(chunkBytes) {
    chunk_.set_manifest(package_->manifest);
    write();
  }
  void OnWriteDone(bool ok) override {
    if (!ok) return Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "write failed"));
    next();
  }
  void OnDone() override { delete this; }

 private:
  void next() {
    chunk_.Clear();
    while (file_ < package_->files.size()) {
      const PackageFile& f = package_->files[file_];
      if (!in_.is_open()) {
        in_.open(f.source, std::ios::binary);
        offset_ = 0;
        if (!in_) return changed(f);
      }
      if (offset_ == f.bytes) {
        in_.close();
        ++file_;
        continue;
      }
      const auto n = static_cast<std::streamsize>(std::min<uint64_t>(buffer_.size(), f.bytes - offset_));
      if (!in_.read(buffer_.data(), n)) return changed(f);
      chunk_.set_path(f.path);
      chunk_.set_offset(offset_);
      chunk_.set_data(buffer_.data(), static_cast<size_t>(n));
      offset_ += static_cast<uint64_t>(n);
      return write();
    }
    Finish(grpc::Status::OK);
  }
  void write() {
    out_ = serialized(chunk_);
    StartWrite(&out_);
  }
  void changed(const PackageFile& f) {
    fmt::print(stderr, "probecast server: the scene file {} cannot be read as it was packaged\n", f.source.string());
    Finish(grpc::Status(grpc::StatusCode::INTERNAL, "the server's copy of " + f.path + " changed or vanished since "
                                                    "the scene was named; the server must be restarted"));
  }

  std::shared_ptr<const ScenePackage> package_;
  std::vector<char> buffer_;
  pb::SceneChunk chunk_;
  grpc::ByteBuffer out_;
  size_t file_ = 0;
  uint64_t offset_ = 0;
  std::ifstream in_;
};

// An edge that has not yet heard from its producer: another edge may have (the client moves on).
grpc::Status notReady() {
  return grpc::Status(grpc::StatusCode::UNAVAILABLE, "no volume yet: this edge has not heard from its producer");
}

class RejectReactor : public RawReactor {
 public:
  explicit RejectReactor(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

class SubscribeReactor;

// Instrumentation: how long frames take from the publish of their newest lighting to gRPC's
// OnWriteDone (the message handed to the transport), over all subscribers.
class FrameWriteTimes {
 public:
  void written(uint64_t serverTimeUs) {
    const uint64_t now = static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                                   std::chrono::system_clock::now().time_since_epoch())
                                                   .count());
    std::lock_guard<std::mutex> lock(mutex_);
    histogram_.record(now - std::min(now, serverTimeUs));
  }
  LatencyHistogram take() {
    std::lock_guard<std::mutex> lock(mutex_);
    LatencyHistogram h = histogram_;
    histogram_.clear();
    return h;
  }

 private:
  std::mutex mutex_;
  LatencyHistogram histogram_;
};

// What the hub's wake-up may touch: the reactor, only while it is alive.
struct ReactorLink {
  std::mutex mutex;
  SubscribeReactor* reactor = nullptr;
};

class SubscribeReactor : public RawReactor {
 public:
  SubscribeReactor(ProbeHub& hub, const ServerConfig& config, std::atomic<uint32_t>& subscribers,
                   FrameWriteTimes& writeTimes, std::string peer)
      : hub_(hub), config_(config), subscribers_(subscribers), writeTimes_(writeTimes), peer_(std::move(peer)),
        link_(std::make_shared<ReactorLink>()) {
    link_->reactor = this;
    StartRead(&inBytes_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      // The client closed its side (a receive-only viewer does so after its hello) or the call
      // broke. A half-closed subscriber keeps its stream: it ends when the client cancels, the
      // call breaks (OnCancel) or the server shuts down. One that never said hello gets nothing.
      if (!id_) finish(invalid("the stream was closed before a hello"));
      return;
    }
    const grpc::Status status = handleBytes();
    if (!status.ok()) {
      finish(status);
      return;
    }
    StartRead(&inBytes_);
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(link_->mutex);
    writing_ = false;
    if (ok && frameServerTimeUs_) writeTimes_.written(frameServerTimeUs_);
    frameServerTimeUs_ = 0;
    if (pendingFinish_) {  // a finish waited for this write, whether it went through or not
      finished_ = true;
      Finish(*pendingFinish_);
      return;
    }
    if (!ok) {
      finishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, "write failed"));
      return;
    }
    tryWriteLocked();
  }

  void OnCancel() override { finish(grpc::Status::CANCELLED); }

  void OnDone() override {
    {
      std::lock_guard<std::mutex> lock(link_->mutex);
      link_->reactor = nullptr;
    }
    if (id_) hub_.removeSubscriber(id_);
    if (counted_) subscribers_--;
    delete this;
  }

  // Called by the hub's wake-up with the link locked.
  void tryWriteLocked() {
    if (writing_ || finished_ || pendingFinish_ || !id_) return;
    if (descriptionPending_) {
      writeDescriptionLocked();
      return;
    }
    if (hub_.streamEnded(id_)) {  // an edge whose producer restarted: what we sent belongs to another epoch
      finishLocked(grpc::Status(grpc::StatusCode::ABORTED, "the stream epoch changed (the producer restarted); "
                                                           "subscribe again"));
      return;
    }
    if (framesSinceStats_ >= kFramesPerStats) {  // a Stats message every kFramesPerStats frames
      sendStatsLocked();
      return;
    }
    // The hub writes the payload straight into the message's one slice: its sections are copied
    // once on their way to the transport.
    grpc_slice slice = grpc_empty_slice();
    const FrameStorage storage = [this, &slice](const OutgoingFrame& f, size_t payloadBytes) {
      if (!stateSerialised_ || !(f.state == state_)) {
        state_ = f.state;
        pb::SceneState w;
        stateToWire(state_, w);
        stateBytes_ = w.SerializeAsString();
        stateSerialised_ = true;
      }
      const FrameFields fields{f.sequence, f.serverTimeUs, payloadBytes, f.keyframes, f.deltas, &stateBytes_, f.sentUs};
      slice = grpc_slice_malloc(framePrefixBytes(fields) + payloadBytes + frameSuffixBytes(fields));
      uint8_t* payload = writeFramePrefix(fields, GRPC_SLICE_START_PTR(slice));
      writeFrameSuffix(fields, payload + payloadBytes);
      return payload;
    };
    const std::optional<OutgoingFrame> frame = hub_.nextFrame(id_, storage);
    if (!frame) {
      grpc_slice_unref(slice);
      // Nothing to send (all held, or a paced link's window is full): a client that acks every
      // frame is still written to every kHeartbeatMs, so it can tell a cut connection from a
      // quiet one (the hub's tick wakes a waiting subscriber every ServerConfig::kTickMs).
      if (heartbeat_ && std::chrono::steady_clock::now() - lastWrite_ >= std::chrono::milliseconds(kHeartbeatMs))
        sendStatsLocked();
      return;
    }
    grpc::Slice message(slice, grpc::Slice::STEAL_REF);
    outBytes_ = grpc::ByteBuffer(&message, 1);
    ++framesSinceStats_;
    frameServerTimeUs_ = frame->serverTimeUs;
    writing_ = true;
    lastWrite_ = std::chrono::steady_clock::now();
    StartWrite(&outBytes_);
  }

 private:
  // A Stats message (the link is locked, no write is in flight).
  void sendStatsLocked() {
    framesSinceStats_ = 0;
    const SubscriberStats st = hub_.stats(id_);
    out_.Clear();
    pb::Stats* s = out_.mutable_stats();
    s->set_bytes_sent(st.bytesSent);
    s->set_bricks_behind(st.bricksBehind);
    s->set_server_frame(hub_.serverFrame());
    s->set_frames_acked(st.framesAcked);
    s->set_ack_rtt_us(st.ackRttUs);
    s->set_link_rate(static_cast<uint64_t>(st.link.rateBytesPerSecond));
    s->set_link_min_rtt_us(st.link.minRttUs);
    s->set_link_window(st.paced ? st.link.windowBytes : 0);
    s->set_link_in_flight(st.link.inFlightBytes);
    s->set_link_waits(st.link.windowWaits);
    if (heartbeat_) s->set_heartbeat_ms(kHeartbeatMs);
    startWriteLocked();
  }

  // The volume description (the link is locked, no write is in flight); frames follow it.
  void writeDescriptionLocked() {
    descriptionPending_ = false;
    out_.Clear();
    pb::VolumeDescription& v = *out_.mutable_volume();
    volumeToWire(hub_.volumeFor(id_), v);
    // A client resuming in this epoch that holds these offsets and this manifest is not sent them
    // again (a 32×8×32 volume's offsets are 24 kB: 0.2 s of a 1 Mbit/s link).
    if (heldEpoch_ == v.stream_epoch() && heldDescription_ == descriptionDigest(v.probe_offsets(), v.scene_manifest())) {
      v.clear_probe_offsets();
      v.clear_scene_manifest();
      v.set_held_parts(true);
    }
    startWriteLocked();
  }

  // A client's mistake: refused with INVALID_ARGUMENT and logged, so a broken client is visible on
  // both ends.
  grpc::Status invalid(const std::string& why) {
    fmt::print(stderr, "probecast server: refusing subscriber {}: {}\n", peer_, why);
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, why);
  }

  // Serialises out_ and writes it; the link is locked, no write is in flight.
  void startWriteLocked() {
    bool own = false;
    outBytes_.Clear();
    grpc::SerializationTraits<pb::ServerMessage>::Serialize(out_, &outBytes_, &own);
    writing_ = true;
    lastWrite_ = std::chrono::steady_clock::now();
    StartWrite(&outBytes_);
  }

  grpc::Status handleBytes() {
    const size_t size = inBytes_.Length();
    const size_t limit = id_ ? config_.maxMessageBytes : helloLimit(config_, hub_.layout());
    if (size > limit)
      return invalid("message of " + std::to_string(size) + " bytes exceeds the limit of " + std::to_string(limit));
    in_.Clear();
    if (!grpc::SerializationTraits<pb::ClientMessage>::Deserialize(&inBytes_, &in_).ok())
      return invalid("a message of " + std::to_string(size) + " bytes is not a valid probecast.v1.ClientMessage");
    return handle(in_);
  }

  grpc::Status handle(const pb::ClientMessage& m) {
    if (!id_) {
      if (!m.has_hello()) return invalid("the first message must be hello");
      return handleHello(m.hello());
    }
    switch (m.kind_case()) {
      case pb::ClientMessage::kHello: return invalid("hello sent twice");
      case pb::ClientMessage::kViews: {
        std::vector<View> views;
        std::string why;
        if (!viewsFromWire(m.views(), config_.maxViews, views, why)) return invalid(why);
        hub_.setViews(id_, std::move(views));
        return grpc::Status::OK;
      }
      case pb::ClientMessage::kAck: {
        std::string why;
        if (!hub_.acknowledge(id_, m.ack().frame_sequence(), why)) return invalid(why);
        return grpc::Status::OK;
      }
      default: return invalid("empty client message");
    }
  }

  grpc::Status handleHello(const pb::Hello& h) {
    if (h.protocol_version() != kProtocolVersion)
      return invalid("protocol version " + std::to_string(h.protocol_version()) + " not supported (server speaks " +
                     std::to_string(kProtocolVersion) + ")");
    if (!hub_.ready()) return notReady();
    const StreamLayout layout = hub_.layout();
    // An open enum: any int32 may arrive, and a narrowing cast would read 260 as 4 (l2).
    const int wanted = h.representation();
    if (!pb::Representation_IsValid(wanted))
      return invalid("representation " + std::to_string(wanted) + " is not a known Representation");
    const int served = static_cast<int>(layout.repr);
    const Representation repr =
        wanted == pb::REPRESENTATION_UNSPECIFIED ? layout.repr : static_cast<Representation>(wanted);
    if (!canTranscode(layout.repr, repr))
      return invalid("representation " + pb::Representation_Name(h.representation()) + " is not served (this server "
                     "streams " + pb::Representation_Name(static_cast<pb::Representation>(served)) +
                     " and transcodes it only to coarser ones)");
    const uint32_t bricks = brickCount(layout);
    if (static_cast<uint32_t>(h.held_size()) > bricks) return invalid("more held bricks than the volume has");
    std::vector<HeldBrick> held;
    for (const auto& b : h.held()) {
      if (b.brick() >= bricks) return invalid("held brick " + std::to_string(b.brick()) + " is outside the volume");
      held.push_back({b.brick(), b.version()});
    }
    if (++subscribers_ > config_.maxSubscribers) {
      --subscribers_;
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "subscriber limit reached");
    }
    counted_ = true;
    std::weak_ptr<ReactorLink> weak = link_;
    const uint64_t id = hub_.addSubscriber(
        h.budget_bytes_per_second(), h.stream_epoch(), held,
        [weak] {
          if (auto link = weak.lock()) {
            std::lock_guard<std::mutex> lock(link->mutex);
            if (link->reactor) link->reactor->tryWriteLocked();
          }
        },
        repr, config_.linkPacing && h.acks_every_frame());
    std::lock_guard<std::mutex> lock(link_->mutex);
    id_ = id;
    heartbeat_ = h.acks_every_frame();
    if (h.stream_epoch() != 0 && h.held_description().size() == 32) {
      heldEpoch_ = h.stream_epoch();
      heldDescription_ = h.held_description();
    }
    if (heartbeat_) {
      // A small Stats first, with the heartbeat promise: the client hears within a round trip that
      // this connection works, however long the description takes over a slow link (its silence
      // watchdog would otherwise cut a fresh connection that is still receiving it).
      descriptionPending_ = true;
      sendStatsLocked();
      return grpc::Status::OK;
    }
    writeDescriptionLocked();  // the volume description first; frames follow from OnWriteDone
    return grpc::Status::OK;
  }

  void finish(const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(link_->mutex);
    finishLocked(status);
  }
  void finishLocked(const grpc::Status& status) {
    if (finished_ || pendingFinish_) return;
    if (writing_) {
      pendingFinish_ = status;  // finish once the write in flight completes
      return;
    }
    finished_ = true;
    Finish(status);
  }

  ProbeHub& hub_;
  const ServerConfig& config_;
  std::atomic<uint32_t>& subscribers_;
  FrameWriteTimes& writeTimes_;
  const std::string peer_;
  std::shared_ptr<ReactorLink> link_;
  grpc::ByteBuffer inBytes_, outBytes_;
  pb::ClientMessage in_;
  pb::ServerMessage out_;
  static constexpr uint32_t kFramesPerStats = 16;
  static constexpr uint32_t kHeartbeatMs = 1000;
  uint64_t heldEpoch_ = 0;        // the epoch and digest of the description a resuming client holds
  std::string heldDescription_;  // (Hello.held_description)
  bool descriptionPending_ = false;  // a paced client's first Stats went first; the description is next
  bool heartbeat_ = false;  // the client acks every frame: it is written to at least every kHeartbeatMs
  std::chrono::steady_clock::time_point lastWrite_{};
  uint32_t framesSinceStats_ = 0;
  uint64_t frameServerTimeUs_ = 0;  // of the frame being written (0: no frame in flight)
  bus::SceneState state_;           // the scene state last serialised, and its bytes
  std::string stateBytes_;
  bool stateSerialised_ = false;
  uint64_t id_ = 0;
  bool counted_ = false;
  bool writing_ = false;
  bool finished_ = false;
  std::optional<grpc::Status> pendingFinish_;
};

using RawSubscribeService = pb::ProbeStream::WithRawCallbackMethod_Subscribe<pb::ProbeStream::WithRawCallbackMethod_GetVolume<
    pb::ProbeStream::WithRawCallbackMethod_GetScene<pb::ProbeStream::Service>>>;

constexpr uint32_t kDefaultSceneChunk = 1u << 20, kMaxSceneChunk = 4u << 20;

class Service final : public RawSubscribeService {
 public:
  Service(ProbeHub& hub, const ServerConfig& config) : hub_(hub), config_(config), scene_(config.scene) {}

  void setScene(std::shared_ptr<const ScenePackage> scene) {
    std::lock_guard<std::mutex> lock(sceneMutex_);
    scene_ = std::move(scene);
  }
  std::shared_ptr<const ScenePackage> scene() const {
    std::lock_guard<std::mutex> lock(sceneMutex_);
    return scene_;
  }

  RawReactor* Subscribe(grpc::CallbackServerContext* ctx) override {
    if (!authorized(ctx, config_.token, config_.noAuth))
      return new RejectReactor(grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token"));
    return new SubscribeReactor(hub_, config_, subscribers_, writeTimes_, ctx->peer());
  }

  grpc::ServerUnaryReactor* GetVolume(grpc::CallbackServerContext* ctx, const grpc::ByteBuffer* requestBytes,
                                      grpc::ByteBuffer* responseBytes) override {
    grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
    if (!authorized(ctx, config_.token, config_.noAuth)) {
      reactor->Finish(grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token"));
      return reactor;
    }
    pb::GetVolumeRequest request;
    if (!parseRequest(requestBytes, request)) {
      reactor->Finish(notA<pb::GetVolumeRequest>(requestBytes));
      return reactor;
    }
    if (!hub_.ready()) {
      reactor->Finish(notReady());
      return reactor;
    }
    pb::VolumeDescription response;
    volumeToWire(hub_.volume(), response);
    *responseBytes = serialized(response);
    reactor->Finish(grpc::Status::OK);
    return reactor;
  }

  grpc::ServerWriteReactor<grpc::ByteBuffer>* GetScene(grpc::CallbackServerContext* ctx,
                                                       const grpc::ByteBuffer* requestBytes) override {
    const auto refuse = [](grpc::StatusCode code, const std::string& why) {
      auto* r = new RefusedSceneReactor();
      r->Finish(grpc::Status(code, why));
      return r;
    };
    if (!authorized(ctx, config_.token, config_.noAuth))
      return refuse(grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token");
    pb::GetSceneRequest parsed;
    if (!parseRequest(requestBytes, parsed)) {
      const grpc::Status why = notA<pb::GetSceneRequest>(requestBytes);
      return refuse(why.error_code(), why.error_message());
    }
    const pb::GetSceneRequest* request = &parsed;
    if (request->scene_hash().size() != 32)
      return refuse(grpc::StatusCode::INVALID_ARGUMENT,
                    "scene_hash of " + std::to_string(request->scene_hash().size()) + " bytes (a SHA-256 has 32)");
    if (request->chunk_bytes() > kMaxSceneChunk)
      return refuse(grpc::StatusCode::INVALID_ARGUMENT,
                    "chunk_bytes " + std::to_string(request->chunk_bytes()) + " is above the limit of 4 MiB");
    const std::shared_ptr<const ScenePackage> package = scene();
    const SceneStamp named = hub_.scene();
    const bool mine = package && std::memcmp(package->hash.data(), request->scene_hash().data(), 32) == 0;
    if (!mine && named.known() && std::memcmp(named.hash.data(), request->scene_hash().data(), 32) == 0) {
      ctx->AddTrailingMetadata(kSceneRetryMetadata, "250");
      return refuse(grpc::StatusCode::UNAVAILABLE, "this server is still getting the files of scene " +
                                                      shortHex(named.hash) + ", which its stream names: ask again shortly");
    }
    if (!mine)
      return refuse(grpc::StatusCode::NOT_FOUND,
                    package ? "this server delivers scene " + shortHex(package->hash) + ", not the one asked for"
                            : "this server has no scene to deliver (start it with the scene's files)");
    return new SceneReactor(package, request->chunk_bytes() ? request->chunk_bytes() : kDefaultSceneChunk);
  }

  FrameWriteTimes& writeTimes() { return writeTimes_; }

 private:
  ProbeHub& hub_;
  const ServerConfig& config_;
  std::atomic<uint32_t> subscribers_{0};
  FrameWriteTimes writeTimes_;
  mutable std::mutex sceneMutex_;
  std::shared_ptr<const ScenePackage> scene_;
};

}  // namespace

struct ProbeServer::Impl {
  ServerConfig config;
  std::unique_ptr<Service> service;
  std::unique_ptr<grpc::Server> server;
  int port = 0;
  // Refilled byte budgets wake their subscribers even when no lighting is being published.
  std::thread ticker;
  std::mutex tickMutex;
  std::condition_variable tickWake;
  bool stopping = false;
};

namespace {

// Checks the certificate and key before gRPC sees them: gRPC reports a bad pair only as a port it
// could not bind. Throws std::runtime_error saying what is wrong with which of the two.
void checkTlsPair(const std::string& certPem, const std::string& keyPem) {
  const auto lastError = [] {
    char text[256] = "no detail";
    if (const unsigned long e = ERR_get_error()) ERR_error_string_n(e, text, sizeof text);
    ERR_clear_error();
    return std::string(text);
  };
  std::unique_ptr<BIO, decltype(&BIO_free)> certBio(BIO_new_mem_buf(certPem.data(), static_cast<int>(certPem.size())),
                                                    &BIO_free);
  std::unique_ptr<X509, decltype(&X509_free)> cert(PEM_read_bio_X509(certBio.get(), nullptr, nullptr, nullptr),
                                                   &X509_free);
  if (!cert) throw std::runtime_error("the TLS certificate is not a PEM certificate (" + lastError() + ")");
  std::unique_ptr<BIO, decltype(&BIO_free)> keyBio(BIO_new_mem_buf(keyPem.data(), static_cast<int>(keyPem.size())),
                                                   &BIO_free);
  std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)> key(
      PEM_read_bio_PrivateKey(keyBio.get(), nullptr, nullptr, nullptr), &EVP_PKEY_free);
  if (!key)
    throw std::runtime_error("the TLS key is not an unencrypted PEM private key (" + lastError() + ")");
  if (X509_check_private_key(cert.get(), key.get()) != 1) {
    ERR_clear_error();
    throw std::runtime_error("the TLS key does not match the certificate (it is the private key of another "
                             "certificate)");
  }
}

}  // namespace

ProbeServer::ProbeServer(const ServerConfig& config, ProbeHub& hub) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.config = config;
  if (config.token.empty() && !config.noAuth)
    throw std::runtime_error("refusing to serve without authentication: give a token, or ask for noAuth");
  if (!config.token.empty() && config.noAuth) throw std::runtime_error("a token and noAuth contradict each other");
  std::shared_ptr<grpc::ServerCredentials> creds;
  const bool tls = !config.tlsCertPem.empty() || !config.tlsKeyPem.empty();
  if (tls) {
    if (config.tlsCertPem.empty() || config.tlsKeyPem.empty())
      throw std::runtime_error("TLS needs both a certificate and a key");
    checkTlsPair(config.tlsCertPem, config.tlsKeyPem);
    grpc::SslServerCredentialsOptions options;
    options.pem_key_cert_pairs.push_back({config.tlsKeyPem, config.tlsCertPem});
    creds = grpc::SslServerCredentials(options);
  } else if (config.plaintext) {
    creds = grpc::InsecureServerCredentials();
  } else {
    throw std::runtime_error("refusing to serve without TLS: give a certificate and key, or ask for plaintext");
  }
  s.service = std::make_unique<Service>(hub, s.config);
  grpc::EnableDefaultHealthCheckService(true);
  grpc::ServerBuilder builder;
  builder.AddListeningPort(config.listen, creds, &s.port);
  builder.RegisterService(s.service.get());
  // gRPC's own cap sits above ours so an oversized message reaches the reactor's clear refusal.
  // An edge learns its layout from the bus later: its cap covers a Hello of a million bricks.
  const StreamLayout layout = hub.layout();
  const size_t hello = isValidLayout(layout) ? helloLimit(config, layout) : config.maxMessageBytes + (size_t{16} << 20);
  const size_t cap = std::max<size_t>({size_t{config.maxMessageBytes} * 4, size_t{1} << 20, hello * 2});
  builder.SetMaxReceiveMessageSize(static_cast<int>(std::min<size_t>(cap, size_t{1} << 30)));
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, config.minClientPingMs);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, config.keepaliveMs);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, config.keepaliveTimeoutMs);
  s.server = builder.BuildAndStart();
  if (!s.server || s.port == 0) throw std::runtime_error("cannot listen on " + config.listen);
  if (auto* health = s.server->GetHealthCheckService()) health->SetServingStatus("probecast.v1.ProbeStream", true);
  s.ticker = std::thread([&s, &hub] {
    std::unique_lock<std::mutex> lock(s.tickMutex);
    while (!s.tickWake.wait_for(lock, std::chrono::milliseconds(ServerConfig::kTickMs), [&s] { return s.stopping; })) {
      lock.unlock();
      hub.tick();
      lock.lock();
    }
  });
}

ProbeServer::~ProbeServer() { shutdown(); }

int ProbeServer::port() const { return impl_->port; }

void ProbeServer::setScene(std::shared_ptr<const ScenePackage> scene) { impl_->service->setScene(std::move(scene)); }

LatencyHistogram ProbeServer::takeFrameWriteLatency() { return impl_->service->writeTimes().take(); }

void ProbeServer::shutdown() {
  {
    std::lock_guard<std::mutex> lock(impl_->tickMutex);
    impl_->stopping = true;
  }
  impl_->tickWake.notify_all();
  if (impl_->ticker.joinable()) impl_->ticker.join();
  if (!impl_->server) return;
  impl_->server->Shutdown(std::chrono::system_clock::now() + std::chrono::milliseconds(500));
  impl_->server->Wait();
  impl_->server.reset();
}

}  // namespace probecast::service
