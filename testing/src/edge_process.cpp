#include "probecast/testing/edge_process.h"

#include <pthread.h>
#include <signal.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace probecast::testing {
namespace {

// The child: an edge until SIGTERM. The signal is blocked before any thread starts, so every
// thread inherits the block and only sigwait takes it.
int runEdge(const service::EdgeConfig& config, const ChildProcess::Say& say) {
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &term, nullptr);
  service::EdgeServer edge(config);
  say("port " + std::to_string(edge.port()));
  int sig = 0;
  sigwait(&term, &sig);
  edge.shutdown();
  return 0;
}

}  // namespace

EdgeProcess::EdgeProcess(const service::EdgeConfig& config)
    : child_([config](const ChildProcess::Say& say) { return runEdge(config, say); }) {}

EdgeProcess::~EdgeProcess() {
  if (started_ && !ended_) stop();  // an unstarted child is released by ChildProcess itself
}

int EdgeProcess::start() {
  child_.go();
  started_ = true;
  std::string line;
  int port = 0;
  if (!child_.readLine(line) || std::sscanf(line.c_str(), "port %d", &port) != 1)
    throw std::runtime_error("edge process did not start");
  return port;
}

void EdgeProcess::kill() {
  child_.signal(SIGKILL);
  child_.wait();
  ended_ = true;
}

void EdgeProcess::freeze() { child_.signal(SIGSTOP); }

void EdgeProcess::thaw() { child_.signal(SIGCONT); }

int EdgeProcess::stop() {
  child_.signal(SIGCONT);  // a frozen child would hold SIGTERM until it runs again
  child_.signal(SIGTERM);
  ended_ = true;
  return child_.wait();
}

}  // namespace probecast::testing
