// A nats-server process with JetStream, for tests and benchmarks: on a free loopback port, its
// store in a temporary folder (removed when it goes) unless one is given, a random token required
// of clients, TLS when given a certificate; stopped and started again on the same port and store,
// as an operator restarting it would.
#pragma once

#include <sys/types.h>

#include <string>

#include "probecast/service/bus_nats.h"

namespace probecast::testing {

// A loopback port free now (the kernel's pick); a server told to listen there next gets it.
int freeLoopbackPort();

struct NatsServerOptions {
  std::string storeDir;         // JetStream's store; empty: a temporary folder
  std::string tlsCert, tlsKey;  // PEM files: clients must speak TLS; none: plaintext (loopback)
};

class NatsServer {
 public:
  // nats-server on PATH, else in /usr/sbin or /usr/bin; empty when there is none.
  static std::string findProgram();
  // Starts it and waits until it accepts connections (at most 10 s). std::runtime_error when the
  // program is missing (it is a dependency: scripts/setup.sh installs it) or does not come up.
  // It requires a token of its own (token()) from every client, as a deployment should.
  explicit NatsServer(const NatsServerOptions& options = {});
  ~NatsServer();  // stops it; removes a temporary store
  NatsServer(const NatsServer&) = delete;
  NatsServer& operator=(const NatsServer&) = delete;

  int port() const { return port_; }
  std::string url() const;  // nats://127.0.0.1:PORT
  const std::string& token() const { return token_; }
  bool tls() const { return !options_.tlsCert.empty(); }
  // A bus link to it for `stream`: its URL and token, TLS trusting its certificate when it has one,
  // plaintext otherwise.
  service::BusConfig bus(const std::string& stream) const;
  const std::string& storeDir() const { return store_; }
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }  // -1 while stopped
  // SIGTERM, then SIGKILL after 5 s; waits for it to end.
  void stop();
  // Starts it again on the same port and store (after stop()).
  void start();

 private:
  NatsServerOptions options_;
  std::string program_, store_, token_;
  bool temporary_ = false;
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace probecast::testing
