// The producer's side of the bus: every brick version a hub makes, published to JetStream.
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>

#include <unistd.h>

#include "nats_link.h"
#include "probecast/service/bus_format.h"
#include "probecast/service/bus_nats.h"

namespace probecast::service {

struct BusPublisher::Impl {
  BusConfig config;
  ProbeHub& hub;
  std::mutex mutex;  // everything below
  std::condition_variable wake;
  std::map<uint32_t, BrickVersionBytes> pending;  // the newest unsent version per brick
  bool stopping = false, needStream = true, resync = false, purge = true, busy = false;
  std::string failure;  // an acknowledgement that came back refused, from the library's thread
  PublisherStats stats;
  uint64_t volumeEpochSent = 0;  // the producer's epoch of the last volume message the bus acknowledged
  // The claim on the stream: who this publisher is (host, process, a random number), the sequence
  // of its newest claim message (0 before the first) and when to renew it.
  std::string identity;
  uint64_t claimSequence = 0;
  std::chrono::steady_clock::time_point renewAt{};
  std::unique_ptr<NatsLink> link;
  std::thread worker;

  Impl(const BusConfig& c, ProbeHub& h) : config(c), hub(h) {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    identity = "probecast producer " + std::string(host) + " pid " + std::to_string(getpid()) + " id " +
               std::to_string(std::random_device{}());
  }

  // The newest claim on the stream: its sequence (0 when there is none) and its text.
  bool lastClaim(uint64_t& sequence, std::string& holder, std::string& why) {
    natsMsg* msg = nullptr;
    jsOptions jo = link->requestOptions();
    jsErrCode code = static_cast<jsErrCode>(0);
    const natsStatus s = js_GetLastMsg(&msg, link->jetStream(), busStreamName(config.stream).c_str(),
                                       producerSubject(config.stream).c_str(), &jo, &code);
    if (s == NATS_NOT_FOUND || code == JSNoMessageFoundErr) {
      sequence = 0;
      holder.clear();
      return true;
    }
    if (s != NATS_OK) return why = "cannot read the stream's producer claim: " + natsErrorText(s, code), false;
    sequence = natsMsg_GetSequence(msg);
    holder.assign(natsMsg_GetData(msg), static_cast<size_t>(natsMsg_GetDataLength(msg)));
    natsMsg_Destroy(msg);
    return true;
  }

  enum class Claim { Held, Lost, Failed };

  // Publishes this publisher's claim, accepted only while the claim subject's newest message is
  // sequence `expected` (0: no condition, for a subject that held nothing).
  Claim publishClaim(uint64_t expected, std::string& why) {
    jsPubOptions po;
    jsPubOptions_Init(&po);
    po.MaxWait = config.requestTimeoutMs;
    po.ExpectLastSubjectSeq = expected;
    jsPubAck* ack = nullptr;
    jsErrCode code = static_cast<jsErrCode>(0);
    const natsStatus s = js_Publish(&ack, link->jetStream(), producerSubject(config.stream).c_str(), identity.data(),
                                    static_cast<int>(identity.size()), &po, &code);
    if (s == NATS_OK) {
      claimSequence = ack->Sequence;
      jsPubAck_Destroy(ack);
      renewAt = std::chrono::steady_clock::now() + std::chrono::milliseconds(config.claimRenewMs);
      return Claim::Held;
    }
    if (code == JSStreamWrongLastSequenceErr) return Claim::Lost;
    why = "cannot claim stream " + busStreamName(config.stream) + ": " + natsErrorText(s, code);
    return Claim::Failed;
  }

  // Makes sure this publisher owns the stream before it purges or publishes: keeps its own claim,
  // takes over one that is not renewed for two renewal periods, claims a stream nobody holds.
  // Returns Lost when another producer holds it (why says who).
  Claim claim(std::string& why) {
    uint64_t sequence = 0;
    std::string holder;
    if (!lastClaim(sequence, holder, why)) return Claim::Failed;
    if (sequence != 0 && holder == identity) return publishClaim(sequence, why);
    if (sequence != 0) {
      if (claimSequence != 0) {  // this publisher held the stream, and another producer took it over
        why = "another producer took stream " + busStreamName(config.stream) + " over (" + holder + ")";
        return Claim::Lost;
      }
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait_for(lock, std::chrono::milliseconds(2LL * config.claimRenewMs), [this] { return stopping; });
        if (stopping) return why = "stopping", Claim::Failed;
      }
      uint64_t now = 0;
      if (!lastClaim(now, holder, why)) return Claim::Failed;
      if (now != sequence) {
        why = "stream " + busStreamName(config.stream) + " has a live producer (" + holder +
              "): stop it, or publish under another --stream";
        return Claim::Lost;
      }
    }
    const Claim c = publishClaim(sequence, why);
    if (c == Claim::Lost)
      why = "another producer claimed stream " + busStreamName(config.stream) + " at the same moment";
    return c;
  }

  static void refused(jsCtx*, jsPubAckErr* pae, void* self) {
    auto* s = static_cast<Impl*>(self);
    std::lock_guard<std::mutex> lock(s->mutex);
    s->failure = "the bus refused a message: " + natsErrorText(pae->Err, pae->ErrCode) +
                 (pae->ErrText ? std::string(" ") + pae->ErrText : std::string());
  }

  // Creates the stream or brings its limits up to date, and claims it; the first time, drops the
  // volume an earlier producer left. Sets `lost` when another producer owns the stream.
  bool ensureStream(bool purgeIt, bool& lost, std::string& why) {
    const std::string name = busStreamName(config.stream), subjects = busSubjects(config.stream),
                      claims = producerSubject(config.stream);
    const char* subjectList[] = {subjects.c_str(), claims.c_str()};
    jsStreamConfig sc;
    jsStreamConfig_Init(&sc);
    sc.Name = name.c_str();
    sc.Subjects = subjectList;
    sc.SubjectsLen = 2;
    sc.Retention = js_LimitsPolicy;
    sc.Storage = js_FileStorage;
    sc.MaxMsgsPerSubject = 1;  // the newest version of each brick is all anyone needs
    sc.MaxAge = 0;             // lighting does not expire; a new producer replaces it
    sc.Discard = js_DiscardOld;
    jsOptions jo = link->requestOptions();
    jsErrCode code = static_cast<jsErrCode>(0);
    jsStreamInfo* info = nullptr;
    natsStatus s = js_AddStream(&info, link->jetStream(), &sc, &jo, &code);
    if (s != NATS_OK && code == JSStreamNameExistErr) {
      code = static_cast<jsErrCode>(0);
      s = js_UpdateStream(&info, link->jetStream(), &sc, &jo, &code);
    }
    if (info) jsStreamInfo_Destroy(info);
    if (s != NATS_OK) return why = "cannot create stream " + name + ": " + natsErrorText(s, code), false;
    const Claim c = claim(why);
    lost = c == Claim::Lost;
    if (c != Claim::Held) return false;
    jo.Stream.Purge.Subject = subjects.c_str();  // the claim stays
    if (purgeIt && (s = js_PurgeStream(link->jetStream(), name.c_str(), &jo, &code)) != NATS_OK)
      return why = "cannot purge stream " + name + ": " + natsErrorText(s, code), false;
    return true;
  }

  // Publishes the batch (and the volume first when `withVolume`), then waits for every acknowledgement.
  bool publish(const std::map<uint32_t, BrickVersionBytes>& batch, bool withVolume, PublisherStats& sent,
               std::string& why) {
    bus::Volume volume = hub.volume();
    // A new epoch (the probe offsets changed) needs its description out before its bricks: the
    // brick messages carry only the offsets' checksum.
    withVolume = withVolume || volume.epoch != volumeEpochSent;
    std::vector<uint8_t> message;
    jsPubOptions po;
    jsPubOptions_Init(&po);
    po.MaxWait = config.requestTimeoutMs;
    const auto send = [&](const std::string& subject) {
      const natsStatus s = js_PublishAsync(link->jetStream(), subject.c_str(), message.data(),
                                           static_cast<int>(message.size()), &po);
      if (s != NATS_OK) return why = "publish on " + subject + ": " + natsErrorText(s), false;
      sent.bytes += message.size();
      ++sent.messages;
      return true;
    };
    if (withVolume) {
      bus::writeVolumeMessage(volume, batch.empty() ? bus::kEndOfBatch : 0, message);
      if (!send(volumeSubject(config.stream))) return false;
    }
    size_t left = batch.size();
    for (const auto& [brick, v] : batch) {
      volume.publishedUs = v.publishedUs;
      bus::writeBrickMessage(volume, busBrick(v), --left == 0 ? bus::kEndOfBatch : 0, message);
      if (!send(brickSubject(config.stream, brick))) return false;
      sent.keyframeBytes += v.keyframe.size();
      sent.deltaBytes += v.delta.size();
    }
    const natsStatus s = js_PublishAsyncComplete(link->jetStream(), &po);
    if (s != NATS_OK) {
      natsMsgList lost;
      if (js_PublishAsyncGetPendingList(&lost, link->jetStream()) == NATS_OK) natsMsgList_Destroy(&lost);
      return why = "the bus did not acknowledge every message: " + natsErrorText(s), false;
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (!failure.empty()) {
      why = failure;
      failure.clear();
      return false;
    }
    if (withVolume) volumeEpochSent = volume.epoch;
    return true;
  }

  // Gives the stream up for good: another producer owns it.
  void displaced(const std::string& why) {
    stats.displaced = true;
    stats.lastError = why;
    pending.clear();
    busy = false;
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping && !stats.displaced) {
      wake.wait_for(lock, std::chrono::milliseconds(200), [this] {
        return stopping || (link->connected() && (needStream || resync || !pending.empty()));
      });
      if (stopping) break;
      if (link->connected() && !needStream && std::chrono::steady_clock::now() >= renewAt) {
        lock.unlock();
        std::string why;
        const Claim c = publishClaim(claimSequence, why);
        lock.lock();
        if (c == Claim::Lost) {
          displaced("another producer took stream " + busStreamName(config.stream) + " over");
          break;
        }
        if (c == Claim::Failed) needStream = true;  // the server may have lost the stream: claim it anew
      }
      if (!link->connected() || !(needStream || resync || !pending.empty())) continue;
      busy = true;
      if (needStream) {
        const bool purgeIt = purge;
        lock.unlock();
        std::string why;
        bool lost = false;
        const bool ok = ensureStream(purgeIt, lost, why);
        lock.lock();
        if (lost) {
          displaced(why);
          break;
        }
        if (!ok) {
          stats.lastError = why;
          busy = false;
          wake.wait_for(lock, std::chrono::milliseconds(200), [this] { return stopping; });
          continue;
        }
        purge = false;
        needStream = false;
        resync = true;
      }
      const bool all = resync;
      resync = false;
      std::map<uint32_t, BrickVersionBytes> batch;
      batch.swap(pending);
      lock.unlock();
      if (all)
        for (BrickVersionBytes& v : hub.currentBricks()) {
          auto it = batch.find(v.brick);
          if (it == batch.end() || it->second.version < v.version) batch[v.brick] = std::move(v);
        }
      PublisherStats sent;
      std::string why;
      const bool ok = publish(batch, all, sent, why);
      lock.lock();
      busy = false;
      if (all) ++stats.resyncs;
      if (ok) {
        stats.messages += sent.messages;
        stats.bytes += sent.bytes;
        stats.keyframeBytes += sent.keyframeBytes;
        stats.deltaBytes += sent.deltaBytes;
      } else {  // the stream may be gone or the server away: make sure of the stream, then send all again
        stats.lastError = why;
        needStream = true;
        wake.wait_for(lock, std::chrono::milliseconds(100), [this] { return stopping; });
      }
    }
  }
};

BusPublisher::BusPublisher(const BusConfig& config, ProbeHub& hub) : impl_(std::make_shared<Impl>(config, hub)) {
  std::string why;
  if (!checkBusConfig(config, why)) throw std::invalid_argument(why);
  Impl& s = *impl_;
  s.link = std::make_unique<NatsLink>(
      config,
      [&s] {  // every (re)connect: the server may have lost the stream or messages
        std::lock_guard<std::mutex> lock(s.mutex);
        s.needStream = true;
        s.wake.notify_all();
      },
      [&s] { s.wake.notify_all(); }, &Impl::refused, &s);
  s.worker = std::thread([&s] { s.run(); });
  hub.setBusOutput([weak = std::weak_ptr<Impl>(impl_)](std::vector<BrickVersionBytes> made) {
    const std::shared_ptr<Impl> self = weak.lock();
    if (!self) return;
    std::lock_guard<std::mutex> lock(self->mutex);
    if (self->stopping || self->stats.displaced) return;
    for (BrickVersionBytes& v : made)
      if (!self->pending.insert_or_assign(v.brick, std::move(v)).second) ++self->stats.superseded;
    self->wake.notify_all();
  });
}

BusPublisher::~BusPublisher() {
  Impl& s = *impl_;
  s.hub.setBusOutput(nullptr);
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.stopping = true;
  }
  s.wake.notify_all();
  if (s.worker.joinable()) s.worker.join();
  s.link.reset();
}

PublisherStats BusPublisher::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  PublisherStats st = impl_->stats;
  st.connected = impl_->link->connected();
  if (!st.connected && st.lastError.empty()) st.lastError = "bus: " + impl_->link->downReason();
  return st;
}

bool BusPublisher::caughtUp() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const Impl& s = *impl_;
  return s.link->connected() && !s.stats.displaced && !s.busy && !s.needStream && !s.resync && s.pending.empty();
}

}  // namespace probecast::service
