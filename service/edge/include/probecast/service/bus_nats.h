// The probe bus on NATS JetStream: names, and the producer's side (BusPublisher). Messages are
// the bus format (bus_format.h); NATS only carries and keeps them.
//
// One stream per probe volume, PROBECAST_<name>, capturing probecast.<name>.> :
//   probecast.<name>.volume      the volume description (epoch, layout, bounds)
//   probecast.<name>.brick.<id>  the newest version of brick <id>: its keyframe and its delta
// The stream keeps one message per subject (file storage, no age limit), which is everything a
// late edge needs: the newest version of every brick, decodable alone, with the delta for
// holders one version behind. The cost is bytes on the bus: every version carries its keyframe
// besides its delta.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "probecast/service/probe_hub.h"

namespace probecast::service {

struct BusConfig {
  std::string url = "nats://127.0.0.1:4222";  // nats://host:port (several comma-separated)
  std::string stream = "probes";              // the volume's name on the bus
  int reconnectWaitMs = 100;                  // between reconnect attempts (forever)
  int requestTimeoutMs = 2000;                // JetStream requests and publish acknowledgements
  int claimRenewMs = 1000;                    // a producer renews its claim on the stream this often
  // Who may write the bus may light every viewer of the stream, so a link is never open by
  // accident: a token (the nats-server's authorization token) or a credentials file (user JWT and
  // NKey seed, NATS .creds), or noAuth said outright; and TLS (trusting caFile, else the system's
  // roots) or plaintext said outright.
  std::string token;
  std::string credsFile;
  bool noAuth = false;
  bool tls = false;
  std::string caFile;
  bool plaintext = false;
};

// A stream name is part of subjects and of the JetStream name: letters, digits, '-' and '_', at
// most 64. A URL is nats://host:port (or several, comma-separated). Credentials and TLS as
// BusConfig says (a token of printable ASCII without spaces). False with `why` otherwise.
bool checkBusConfig(const BusConfig& config, std::string& why);
std::string busStreamName(const std::string& stream);
std::string busSubjects(const std::string& stream);  // probecast.<name>.>
std::string volumeSubject(const std::string& stream);
std::string brickSubject(const std::string& stream, uint32_t brick);
// Where the producer that owns the stream renews its claim: probecast-producer.<name>, in the
// stream but outside the subjects edges consume.
std::string producerSubject(const std::string& stream);

struct PublisherStats {
  bool connected = false;
  uint64_t messages = 0;   // brick and volume messages the bus acknowledged
  uint64_t bytes = 0;      // their bytes
  uint64_t keyframeBytes = 0, deltaBytes = 0;  // of which brick sections: keyframes, deltas
  uint64_t superseded = 0; // brick versions replaced by a newer one before they went out
  uint32_t resyncs = 0;    // times every brick was published again (after a reconnect or a failure)
  bool displaced = false;  // another producer owns the stream: this one has stopped publishing for good
  std::string lastError;
};

// Publishes every brick version a producer's hub makes, and its volume, to the bus. Connects in
// the background and keeps reconnecting; on every (re)connect it creates or updates the stream
// and publishes the current version of every brick again (the server may have lost messages or
// its whole store). The first connect purges what an earlier producer left under the name. A
// bus that is slow or away never slows the producer: versions of a brick not yet sent are
// replaced by newer ones.
//
// One producer per stream: before purging, a publisher claims the stream on producerSubject and
// renews the claim every claimRenewMs, each renewal conditional on the subject's last sequence
// being its own. A claim left by another producer is taken over only when it is not renewed for
// two renewal periods (that producer stopped); a live one leaves this publisher displaced
// (PublisherStats::displaced, with the reason in lastError) without touching the stream. A
// producer whose renewal finds another's claim (it took over while this one was cut off) stops
// publishing the same way.
class BusPublisher {
 public:
  // Throws std::invalid_argument for a bad config (checkBusConfig). The hub must outlive this.
  BusPublisher(const BusConfig& config, ProbeHub& hub);
  // Detaches from the hub, stops, closes the connection (a publish running meanwhile on another
  // thread hands its versions to nothing).
  ~BusPublisher();
  BusPublisher(const BusPublisher&) = delete;
  BusPublisher& operator=(const BusPublisher&) = delete;

  PublisherStats stats() const;
  // True once every version the hub made so far has been acknowledged by the bus (for tests and
  // tools); never while displaced.
  bool caughtUp() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;  // shared with the hub's output while a publish hands it versions
};

}  // namespace probecast::service
