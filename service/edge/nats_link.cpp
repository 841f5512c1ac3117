#include "nats_link.h"

#include <stdexcept>

namespace probecast::service {
namespace {

bool validStreamChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
}

}  // namespace

bool checkBusConfig(const BusConfig& c, std::string& why) {
  if (c.stream.empty() || c.stream.size() > 64)
    return why = "stream name must have 1 to 64 characters", false;
  for (char ch : c.stream)
    if (!validStreamChar(ch))
      return why = "stream name '" + c.stream + "' may hold only letters, digits, '-' and '_'", false;
  if (c.url.empty()) return why = "no NATS URL", false;
  size_t start = 0;
  while (start <= c.url.size()) {
    const size_t end = std::min(c.url.find(',', start), c.url.size());
    const std::string one = c.url.substr(start, end - start);
    if (one.rfind("nats://", 0) != 0 || one.size() <= 7 || one.find(':', 7) == std::string::npos)
      return why = "NATS URL '" + one + "' is not nats://host:port", false;
    start = end + 1;
  }
  if (c.reconnectWaitMs < 1 || c.requestTimeoutMs < 1 || c.claimRenewMs < 1)
    return why = "bus timeouts must be positive", false;
  return true;
}

std::string busStreamName(const std::string& stream) { return "PROBECAST_" + stream; }
std::string busSubjects(const std::string& stream) { return "probecast." + stream + ".>"; }
std::string volumeSubject(const std::string& stream) { return "probecast." + stream + ".volume"; }
std::string brickSubject(const std::string& stream, uint32_t brick) {
  return "probecast." + stream + ".brick." + std::to_string(brick);
}
std::string producerSubject(const std::string& stream) { return "probecast-producer." + stream; }

std::string natsErrorText(natsStatus status, jsErrCode code) {
  std::string text = natsStatus_GetText(status);
  if (code != 0) text += " (JetStream error " + std::to_string(static_cast<int>(code)) + ")";
  natsStatus last = NATS_OK;
  if (const char* detail = nats_GetLastError(&last); detail && *detail && last == status) text += ": " + std::string(detail);
  return text;
}

NatsLink::NatsLink(const BusConfig& config, std::function<void()> onUp, std::function<void()> onDown,
                   jsPubAckErrHandler onRefused, void* refusedClosure)
    : config_(config), onUp_(std::move(onUp)), onDown_(std::move(onDown)) {
  natsStatus s = natsOptions_Create(&options_);
  if (s == NATS_OK) s = natsOptions_SetURL(options_, config.url.c_str());
  if (s == NATS_OK) s = natsOptions_SetMaxReconnect(options_, -1);
  if (s == NATS_OK) s = natsOptions_SetReconnectWait(options_, config.reconnectWaitMs);
  if (s == NATS_OK) s = natsOptions_SetReconnectJitter(options_, 0, 0);
  if (s == NATS_OK) s = natsOptions_SetTimeout(options_, config.requestTimeoutMs);
  // A dead server is noticed within about two seconds, not the default minutes.
  if (s == NATS_OK) s = natsOptions_SetPingInterval(options_, 1000);
  if (s == NATS_OK) s = natsOptions_SetMaxPingsOut(options_, 2);
  if (s == NATS_OK) s = natsOptions_SetReconnectedCB(options_, &NatsLink::up, this);
  if (s == NATS_OK) s = natsOptions_SetDisconnectedCB(options_, &NatsLink::down, this);
  if (s == NATS_OK) s = natsOptions_SetClosedCB(options_, &NatsLink::closed, this);
  if (s == NATS_OK) s = natsOptions_SetRetryOnFailedConnect(options_, true, &NatsLink::up, this);
  if (s != NATS_OK) {
    const std::string why = natsErrorText(s);
    natsOptions_Destroy(options_);
    throw std::runtime_error("NATS options refused: " + why);
  }
  s = natsConnection_Connect(&nc_, options_);
  if (s == NATS_OK) {
    connected_ = true;
  } else if (s != NATS_NOT_YET_CONNECTED) {  // not yet connected: it keeps trying in the background
    const std::string why = natsErrorText(s);
    natsOptions_Destroy(options_);
    throw std::runtime_error("cannot connect to " + config.url + ": " + why);
  }
  jsOptions jo = requestOptions();
  jo.PublishAsync.ErrHandler = onRefused;
  jo.PublishAsync.ErrHandlerClosure = refusedClosure;
  s = natsConnection_JetStream(&js_, nc_, &jo);
  if (s != NATS_OK) {
    const std::string why = natsErrorText(s);
    natsConnection_Destroy(nc_);
    natsOptions_Destroy(options_);
    throw std::runtime_error("no JetStream context: " + why);
  }
  if (connected_ && onUp_) onUp_();
}

NatsLink::~NatsLink() {
  jsCtx_Destroy(js_);
  natsConnection_Close(nc_);
  {  // callbacks run on the library's threads: wait for its last one before this object goes
    std::unique_lock<std::mutex> lock(closeMutex_);
    closeWake_.wait_for(lock, std::chrono::seconds(5), [this] { return closed_; });
  }
  natsConnection_Destroy(nc_);
  natsOptions_Destroy(options_);
}

jsOptions NatsLink::requestOptions() const {
  jsOptions jo;
  jsOptions_Init(&jo);
  jo.Wait = config_.requestTimeoutMs;
  jo.PublishAsync.MaxPending = 4096;
  return jo;
}

void NatsLink::up(natsConnection*, void* self) {
  auto* link = static_cast<NatsLink*>(self);
  link->connected_ = true;
  if (link->onUp_) link->onUp_();
}

void NatsLink::closed(natsConnection*, void* self) {
  auto* link = static_cast<NatsLink*>(self);
  link->connected_ = false;
  std::lock_guard<std::mutex> lock(link->closeMutex_);
  link->closed_ = true;
  link->closeWake_.notify_all();
}

void NatsLink::down(natsConnection*, void* self) {
  auto* link = static_cast<NatsLink*>(self);
  link->connected_ = false;
  if (link->onDown_) link->onDown_();
}

}  // namespace probecast::service
