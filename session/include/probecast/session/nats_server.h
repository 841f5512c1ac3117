// A nats-server process with JetStream, for tests and benchmarks: on a free loopback port, its
// store in a temporary folder (removed when it goes) unless one is given; stopped and started
// again on the same port and store, as an operator restarting it would.
#pragma once

#include <sys/types.h>

#include <string>

namespace probecast::session {

// A loopback port free now (the kernel's pick); a server told to listen there next gets it.
int freeLoopbackPort();

class NatsServer {
 public:
  // nats-server on PATH, else in /usr/sbin or /usr/bin; empty when there is none.
  static std::string findProgram();
  // Starts it and waits until it accepts connections (at most 10 s). std::runtime_error when the
  // program is missing (it is a dependency: scripts/setup.sh installs it) or does not come up.
  explicit NatsServer(const std::string& storeDir = {});
  ~NatsServer();  // stops it; removes a temporary store
  NatsServer(const NatsServer&) = delete;
  NatsServer& operator=(const NatsServer&) = delete;

  int port() const { return port_; }
  std::string url() const;  // nats://127.0.0.1:PORT
  const std::string& storeDir() const { return store_; }
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }  // -1 while stopped
  // SIGTERM, then SIGKILL after 5 s; waits for it to end.
  void stop();
  // Starts it again on the same port and store (after stop()).
  void start();

 private:
  std::string program_, store_;
  bool temporary_ = false;
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace probecast::session
