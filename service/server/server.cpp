// ProbeStream over gRPC's callback API: authentication, validation, one reactor per subscriber.
#include "probecast/service/server.h"

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include "probecast.grpc.pb.h"
#include "wire_convert.h"

namespace probecast::service {
namespace {

namespace pb = probecast::v1;

bool authorized(grpc::CallbackServerContext* ctx, const std::string& token) {
  if (token.empty()) return true;
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

// An edge that has not yet heard from its producer: another edge may have (the client moves on).
grpc::Status notReady() {
  return grpc::Status(grpc::StatusCode::UNAVAILABLE, "no volume yet: this edge has not heard from its producer");
}

class RejectReactor : public grpc::ServerBidiReactor<pb::ClientMessage, pb::ServerMessage> {
 public:
  explicit RejectReactor(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

class SubscribeReactor;

// What the hub's wake-up may touch: the reactor, only while it is alive.
struct ReactorLink {
  std::mutex mutex;
  SubscribeReactor* reactor = nullptr;
};

class SubscribeReactor : public grpc::ServerBidiReactor<pb::ClientMessage, pb::ServerMessage> {
 public:
  SubscribeReactor(ProbeHub& hub, const ServerConfig& config, std::atomic<uint32_t>& subscribers)
      : hub_(hub), config_(config), subscribers_(subscribers), link_(std::make_shared<ReactorLink>()) {
    link_->reactor = this;
    StartRead(&in_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client closed its side or the call broke
      finish(grpc::Status::OK);
      return;
    }
    const grpc::Status status = handle(in_);
    if (!status.ok()) {
      finish(status);
      return;
    }
    StartRead(&in_);
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(link_->mutex);
    writing_ = false;
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
    if (hub_.streamEnded(id_)) {  // an edge whose producer restarted: what we sent belongs to another epoch
      finishLocked(grpc::Status(grpc::StatusCode::ABORTED, "the stream epoch changed (the producer restarted); "
                                                           "subscribe again"));
      return;
    }
    if (framesSinceStats_ >= kFramesPerStats) {  // a Stats message every kFramesPerStats frames
      framesSinceStats_ = 0;
      const SubscriberStats st = hub_.stats(id_);
      out_.Clear();
      pb::Stats* s = out_.mutable_stats();
      s->set_bytes_sent(st.bytesSent);
      s->set_bricks_behind(st.bricksBehind);
      s->set_server_frame(hub_.serverFrame());
      s->set_frames_acked(st.framesAcked);
      s->set_ack_rtt_us(st.ackRttUs);
      writing_ = true;
      StartWrite(&out_);
      return;
    }
    std::optional<OutgoingFrame> frame = hub_.nextFrame(id_);
    if (!frame) return;
    out_.Clear();
    pb::Frame* f = out_.mutable_frame();
    f->set_sequence(frame->sequence);
    f->set_server_time_us(frame->serverTimeUs);
    f->set_payload(reinterpret_cast<const char*>(frame->payload.data()), frame->payload.size());
    f->set_keyframes(frame->keyframes);
    f->set_deltas(frame->deltas);
    ++framesSinceStats_;
    writing_ = true;
    StartWrite(&out_);
  }

 private:
  grpc::Status invalid(const std::string& why) { return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, why); }

  grpc::Status handle(const pb::ClientMessage& m) {
    if (m.ByteSizeLong() > config_.maxMessageBytes)
      return invalid("message of " + std::to_string(m.ByteSizeLong()) + " bytes exceeds the limit of " +
                     std::to_string(config_.maxMessageBytes));
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
    const auto repr = static_cast<uint8_t>(layout.repr);
    if (h.representation() != pb::REPRESENTATION_UNSPECIFIED && static_cast<uint8_t>(h.representation()) != repr)
      return invalid("representation " + pb::Representation_Name(h.representation()) + " is not served (this server "
                     "streams " + pb::Representation_Name(static_cast<pb::Representation>(repr)) + ")");
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
    const uint64_t id = hub_.addSubscriber(h.budget_bytes_per_second(), h.stream_epoch(), held, [weak] {
      if (auto link = weak.lock()) {
        std::lock_guard<std::mutex> lock(link->mutex);
        if (link->reactor) link->reactor->tryWriteLocked();
      }
    });
    std::lock_guard<std::mutex> lock(link_->mutex);
    id_ = id;
    out_.Clear();
    const bus::Volume v = hub_.volume();
    volumeToWire(v.layout, v.bounds, v.epoch, *out_.mutable_volume());
    writing_ = true;
    StartWrite(&out_);  // the volume description first; frames follow from OnWriteDone
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
  std::shared_ptr<ReactorLink> link_;
  pb::ClientMessage in_;
  pb::ServerMessage out_;
  static constexpr uint32_t kFramesPerStats = 16;
  uint32_t framesSinceStats_ = 0;
  uint64_t id_ = 0;
  bool counted_ = false;
  bool writing_ = false;
  bool finished_ = false;
  std::optional<grpc::Status> pendingFinish_;
};

class Service final : public pb::ProbeStream::CallbackService {
 public:
  Service(ProbeHub& hub, const ServerConfig& config) : hub_(hub), config_(config) {}

  grpc::ServerBidiReactor<pb::ClientMessage, pb::ServerMessage>* Subscribe(grpc::CallbackServerContext* ctx) override {
    if (!authorized(ctx, config_.token))
      return new RejectReactor(grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token"));
    return new SubscribeReactor(hub_, config_, subscribers_);
  }

  grpc::ServerUnaryReactor* GetVolume(grpc::CallbackServerContext* ctx, const pb::GetVolumeRequest*,
                                      pb::VolumeDescription* response) override {
    grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
    if (!authorized(ctx, config_.token)) {
      reactor->Finish(grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token"));
      return reactor;
    }
    if (!hub_.ready()) {
      reactor->Finish(notReady());
      return reactor;
    }
    const bus::Volume v = hub_.volume();
    volumeToWire(v.layout, v.bounds, v.epoch, *response);
    reactor->Finish(grpc::Status::OK);
    return reactor;
  }

 private:
  ProbeHub& hub_;
  const ServerConfig& config_;
  std::atomic<uint32_t> subscribers_{0};
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

ProbeServer::ProbeServer(const ServerConfig& config, ProbeHub& hub) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.config = config;
  std::shared_ptr<grpc::ServerCredentials> creds;
  const bool tls = !config.tlsCertPem.empty() || !config.tlsKeyPem.empty();
  if (tls) {
    if (config.tlsCertPem.empty() || config.tlsKeyPem.empty())
      throw std::runtime_error("TLS needs both a certificate and a key");
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
  builder.SetMaxReceiveMessageSize(static_cast<int>(std::max<uint32_t>(config.maxMessageBytes * 4, 1 << 20)));
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
