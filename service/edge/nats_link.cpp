#include "nats_link.h"

#include <stdexcept>

namespace probecast::service {
namespace {

bool validStreamChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
}

// Where the bus is and how to reach it: URL, credentials, TLS, timeout.
natsStatus configure(natsOptions* o, const BusConfig& config) {
  natsStatus s = natsOptions_SetURL(o, config.url.c_str());
  if (s == NATS_OK) s = natsOptions_SetTimeout(o, config.requestTimeoutMs);
  if (s == NATS_OK && !config.token.empty()) s = natsOptions_SetToken(o, config.token.c_str());
  if (s == NATS_OK && !config.credsFile.empty())
    s = natsOptions_SetUserCredentialsFromFiles(o, config.credsFile.c_str(), nullptr);
  if (s == NATS_OK && config.tls) s = natsOptions_SetSecure(o, true);
  if (s == NATS_OK && config.tls && !config.caFile.empty())
    s = natsOptions_LoadCATrustedCertificates(o, config.caFile.c_str());
  return s;
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
  if (!c.token.empty() && !c.credsFile.empty()) return why = "a bus token and a credentials file contradict each other", false;
  const bool credentials = !c.token.empty() || !c.credsFile.empty();
  if (credentials && c.noAuth) return why = "bus credentials and no auth contradict each other", false;
  if (!credentials && !c.noAuth)
    return why = "no credentials for the bus: anyone who reaches it could light every viewer (give a token or a "
                 "credentials file, or ask for no auth on a trusted network)",
           false;
  for (char ch : c.token)
    if (ch <= 0x20 || ch > 0x7e) return why = "the bus token must be printable ASCII without spaces", false;
  if (c.tls && c.plaintext) return why = "bus TLS and plaintext contradict each other", false;
  if (!c.caFile.empty() && !c.tls) return why = "a CA file for the bus needs TLS", false;
  if (!c.tls && !c.plaintext)
    return why = "refusing a bus link without TLS (ask for TLS, or plaintext on a trusted network)", false;
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
  if (s == NATS_OK) s = configure(options_, config);
  if (s == NATS_OK) s = natsOptions_SetMaxReconnect(options_, -1);
  if (s == NATS_OK) s = natsOptions_SetReconnectWait(options_, config.reconnectWaitMs);
  if (s == NATS_OK) s = natsOptions_SetReconnectJitter(options_, 0, 0);
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
  refuseWhatTheBusRefuses(config);
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

void NatsLink::refuseWhatTheBusRefuses(const BusConfig& config) {
  // One attempt first, without retrying: a bus that refuses our credentials or our TLS is a
  // mistake to report now, where the background retries would only ever say "no server".
  natsOptions* once = nullptr;
  natsStatus s = natsOptions_Create(&once);
  if (s == NATS_OK) s = configure(once, config);
  if (s == NATS_OK) s = natsOptions_SetMaxReconnect(once, 0);
  natsConnection* probe = nullptr;
  if (s == NATS_OK) s = natsConnection_Connect(&probe, once);
  const std::string why = s == NATS_OK ? std::string() : natsErrorText(s);
  natsConnection_Destroy(probe);
  natsOptions_Destroy(once);
  const bool refused = s == NATS_CONNECTION_AUTH_FAILED || s == NATS_NOT_PERMITTED || s == NATS_SSL_ERROR ||
                       s == NATS_SECURE_CONNECTION_REQUIRED || s == NATS_SECURE_CONNECTION_WANTED ||
                       s == NATS_INVALID_ARG || s == NATS_ERR;
  firstFailure_ = why;
  if (!refused) return;  // connected, or no server yet: the link keeps trying in the background
  natsOptions_Destroy(options_);
  options_ = nullptr;
  throw std::runtime_error("the bus at " + config.url + " refused the link: " + why);
}

std::string NatsLink::downReason() const {
  if (connected_) return {};
  const char* text = nullptr;
  const natsStatus s = natsConnection_GetLastError(nc_, &text);
  if (s == NATS_OK) return firstFailure_.empty() ? "not connected yet" : firstFailure_;
  return std::string(natsStatus_GetText(s)) + (text && *text ? std::string(": ") + text : std::string());
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
