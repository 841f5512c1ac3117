// A NATS connection that reconnects forever and says when it is up or down (private to the edge
// library).
#pragma once

#include <nats/nats.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>

#include "probecast/service/bus_nats.h"

namespace probecast::service {

std::string natsErrorText(natsStatus status, jsErrCode code = static_cast<jsErrCode>(0));

class NatsLink {
 public:
  // `onUp` runs on a NATS thread after every (re)connect, `onDown` after every disconnect; both
  // must only signal; `onRefused` (optional) gets asynchronous publishes the server refused.
  // Throws std::runtime_error when the client library refuses the options.
  NatsLink(const BusConfig& config, std::function<void()> onUp, std::function<void()> onDown,
           jsPubAckErrHandler onRefused = nullptr, void* refusedClosure = nullptr);
  ~NatsLink();
  NatsLink(const NatsLink&) = delete;
  NatsLink& operator=(const NatsLink&) = delete;

  natsConnection* connection() const { return nc_; }
  jsCtx* jetStream() const { return js_; }
  bool connected() const { return connected_; }
  // Why the link is down (the last error of the connection: a refused token, a TLS failure, no
  // server); empty while it is up.
  std::string downReason() const;
  // JetStream request options with the configured timeout.
  jsOptions requestOptions() const;

 private:
  // Throws std::runtime_error when one attempt to connect is refused (credentials, TLS).
  void refuseWhatTheBusRefuses(const BusConfig& config);
  static void up(natsConnection*, void* self);
  static void down(natsConnection*, void* self);
  static void closed(natsConnection*, void* self);

  BusConfig config_;
  std::function<void()> onUp_, onDown_;
  natsOptions* options_ = nullptr;
  natsConnection* nc_ = nullptr;
  jsCtx* js_ = nullptr;
  std::atomic<bool> connected_{false};
  std::mutex closeMutex_;
  std::condition_variable closeWake_;
  bool closed_ = false;  // the library's last callback for this connection has run
  std::string firstFailure_;  // why the first attempt to connect failed (empty: it did not)
};

}  // namespace probecast::service
