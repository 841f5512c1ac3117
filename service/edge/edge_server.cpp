// An edge server: a JetStream ordered consumer of the volume's subjects, from the newest message
// of each, into an edge hub served over gRPC.
#include "probecast/service/edge_server.h"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "nats_link.h"
#include "probecast/service/bus_format.h"

namespace probecast::service {

struct EdgeServer::Impl {
  EdgeConfig config;
  ProbeHub hub;
  std::unique_ptr<ProbeServer> server;
  mutable std::mutex mutex;  // everything below
  std::condition_variable wake;
  bool stopping = false, wantSubscription = true, subscriptionDone = false;
  natsSubscription* subscription = nullptr;
  EdgeStats stats;
  std::unique_ptr<NatsLink> link;
  std::thread worker, sceneWorker;
  SceneHash servedScene{};

  // Keeps the server's scene package that of the scene the bus names (see EdgeConfig).
  void keepScene() {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping) {
      lock.unlock();
      const SceneStamp stamp = hub.scene();
      std::string error;
      bool retryLater = false;
      if (stamp.known() && stamp.hash != servedScene) {
        ScenePackage p;
        SceneFetch fetch;
        // Without a source, only what the cache holds (or a built-in, whose manifest is all of it).
        const bool ok = config.sceneSource
                            ? fetchScene(*config.sceneSource, stamp, config.sceneCache, config.sceneMaxBytes, p, fetch, error)
                            : findCachedPackage(config.sceneCache, stamp.hash, p) ||
                                  (parseManifest(stamp.manifest, p, error) && p.files.empty());
        if (ok && p.hash == stamp.hash) {
          servedScene = p.hash;
          const std::string what = p.describe();
          server->setScene(std::make_shared<const ScenePackage>(std::move(p)));
          lock.lock();
          stats.scene = what;
          stats.sceneFetch = fetch;
          lock.unlock();
        } else {
          retryLater = true;
          if (error.empty()) error = "the scene's files are not in " + config.sceneCache.string() + " and no --scene-from is given";
        }
      }
      lock.lock();
      if (retryLater) stats.lastError = "scene: " + error;
      wake.wait_for(lock, std::chrono::milliseconds(retryLater ? 5000 : 200), [this] { return stopping; });
    }
  }

  explicit Impl(const EdgeConfig& c) : config(c), hub(c.hub, FromBus{}) {}

  static void onMessage(natsConnection*, natsSubscription*, natsMsg* msg, void* self) {
    static_cast<Impl*>(self)->take(msg);
    natsMsg_Destroy(msg);
  }

  static void onComplete(void* self) {
    auto* s = static_cast<Impl*>(self);
    std::lock_guard<std::mutex> lock(s->mutex);
    s->subscriptionDone = true;
    s->wake.notify_all();
  }

  void take(natsMsg* msg) {
    const auto* data = reinterpret_cast<const uint8_t*>(natsMsg_GetData(msg));
    const size_t size = static_cast<size_t>(std::max(0, natsMsg_GetDataLength(msg)));
    bus::Message m;
    std::string why;
    if (!bus::readMessage(data, size, m, why)) {
      std::lock_guard<std::mutex> lock(mutex);
      stats.received += 1;
      stats.refused += 1;
      stats.lastError = std::string("refused a message on ") + natsMsg_GetSubject(msg) + ": " + why;
      return;
    }
    // Subscribers are woken at the end of a producer's batch, so a lighting update reaches them as
    // one frame rather than one per brick message. A batch whose end never comes (the producer
    // died within it) is still served: the server's tick wakes waiting subscribers every
    // ServerConfig::kTickMs.
    const bool wakeNow = (m.flags & bus::kEndOfBatch) != 0;
    const ProbeHub::Received r = hub.receive(m, wakeNow, why);
    std::lock_guard<std::mutex> lock(mutex);
    stats.received += 1;
    switch (r) {
      case ProbeHub::Received::NewEpoch: stats.epochs += 1; stats.applied += m.kind == bus::Kind::Brick; break;
      case ProbeHub::Received::Applied: stats.applied += 1; break;
      case ProbeHub::Received::Stale: stats.stale += 1; break;
      case ProbeHub::Received::Refused: stats.refused += 1; break;
    }
    if (!why.empty()) stats.lastError = std::string(natsMsg_GetSubject(msg)) + ": " + why;
  }

  // Drops the current subscription, waiting until its handler can no longer run. Lock held on entry.
  void unsubscribe(std::unique_lock<std::mutex>& lock) {
    if (!subscription) return;
    natsSubscription* sub = subscription;
    subscription = nullptr;
    lock.unlock();
    natsSubscription_Unsubscribe(sub);
    lock.lock();
    wake.wait_for(lock, std::chrono::seconds(5), [this] { return subscriptionDone; });
    lock.unlock();
    natsSubscription_Destroy(sub);
    lock.lock();
  }

  bool subscribe(std::string& why) {
    const std::string stream = busStreamName(config.bus.stream), subjects = busSubjects(config.bus.stream);
    jsSubOptions so;
    jsSubOptions_Init(&so);
    so.Stream = stream.c_str();
    so.Ordered = true;  // no acks, no redeliveries; the library restarts it past any gap
    so.Config.DeliverPolicy = js_DeliverLastPerSubject;
    jsOptions jo = link->requestOptions();
    jsErrCode code = static_cast<jsErrCode>(0);
    natsSubscription* sub = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex);
      subscriptionDone = false;
    }
    natsStatus s = js_Subscribe(&sub, link->jetStream(), subjects.c_str(), &Impl::onMessage, this, &jo, &so, &code);
    if (s == NATS_OK) s = natsSubscription_SetOnCompleteCB(sub, &Impl::onComplete, this);
    if (s == NATS_OK) s = natsSubscription_SetPendingLimits(sub, -1, -1);  // the bus never drops what we are slow to take
    if (s != NATS_OK) {
      if (sub) {
        natsSubscription_Unsubscribe(sub);
        natsSubscription_Destroy(sub);
      }
      return why = "cannot subscribe to " + subjects + " in " + stream + ": " + natsErrorText(s, code), false;
    }
    std::lock_guard<std::mutex> lock(mutex);
    subscription = sub;
    return true;
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping) {
      wake.wait_for(lock, std::chrono::milliseconds(200),
                    [this] { return stopping || (wantSubscription && link->connected()); });
      if (stopping) break;
      if (!wantSubscription || !link->connected()) continue;
      // After a reconnect the server may have lost the consumer: start again from the newest of
      // each brick (what is held already comes back as stale).
      unsubscribe(lock);
      wantSubscription = false;
      lock.unlock();
      std::string why;
      const bool ok = subscribe(why);
      lock.lock();
      if (ok) {
        stats.subscribes += 1;
      } else {
        stats.lastError = why;
        wantSubscription = true;
        wake.wait_for(lock, std::chrono::milliseconds(200), [this] { return stopping; });
      }
    }
    unsubscribe(lock);
  }
};

EdgeServer::EdgeServer(const EdgeConfig& config) : impl_(std::make_unique<Impl>(config)) {
  std::string why;
  if (!checkBusConfig(config.bus, why)) throw std::invalid_argument(why);
  Impl& s = *impl_;
  s.server = std::make_unique<ProbeServer>(s.config.server, s.hub);
  s.link = std::make_unique<NatsLink>(
      config.bus,
      [&s] {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.wantSubscription = true;
        s.wake.notify_all();
      },
      [&s] { s.wake.notify_all(); });
  if (s.config.sceneCache.empty()) s.config.sceneCache = defaultSceneCache();
  s.worker = std::thread([&s] { s.run(); });
  s.sceneWorker = std::thread([&s] { s.keepScene(); });
}

EdgeServer::~EdgeServer() { shutdown(); }

int EdgeServer::port() const { return impl_->server ? impl_->server->port() : 0; }

EdgeStats EdgeServer::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  EdgeStats st = impl_->stats;
  st.busConnected = impl_->link && impl_->link->connected();
  if (impl_->link && !st.busConnected && st.lastError.empty()) st.lastError = "bus: " + impl_->link->downReason();
  return st;
}

const ProbeHub& EdgeServer::hub() const { return impl_->hub; }

LatencyHistogram EdgeServer::takeFrameWriteLatency() {
  return impl_->server ? impl_->server->takeFrameWriteLatency() : LatencyHistogram{};
}

void EdgeServer::shutdown() {
  Impl& s = *impl_;
  if (s.server) s.server->shutdown();
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.stopping = true;
  }
  s.wake.notify_all();
  if (s.worker.joinable()) s.worker.join();
  if (s.sceneWorker.joinable()) s.sceneWorker.join();
  s.link.reset();
}

}  // namespace probecast::service
