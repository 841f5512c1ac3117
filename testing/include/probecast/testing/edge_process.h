// An edge server (service::EdgeServer) in a process of its own, for benchmarks that run a
// producer and edges apart. Forked when constructed, so construct it before this process starts
// gRPC; start() releases it and returns the port it listens on.
#pragma once

#include <memory>

#include "probecast/service/edge_server.h"
#include "probecast/testing/child_process.h"

namespace probecast::testing {

class EdgeProcess {
 public:
  explicit EdgeProcess(const service::EdgeConfig& config);
  ~EdgeProcess();  // stops it (SIGTERM) and waits
  EdgeProcess(const EdgeProcess&) = delete;
  EdgeProcess& operator=(const EdgeProcess&) = delete;

  // Releases the child and waits for its port; std::runtime_error when it does not come up.
  int start();
  // SIGKILL: the edge dies at once, its connections cut as a crashed machine's would.
  void kill();
  // SIGSTOP: the edge hangs with its connections open, as a frozen machine does (only keepalive
  // pings notice); thaw() (SIGCONT) lets it run on.
  void freeze();
  void thaw();
  // SIGTERM: it shuts down (ends its streams) and exits; returns its exit status.
  int stop();

 private:
  ChildProcess child_;
  bool started_ = false, ended_ = false;
};

}  // namespace probecast::testing
