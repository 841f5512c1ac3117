// A function run in a process of its own (so its CPU time is its own), forked when constructed
// and released by go(). Fork every child before this process starts gRPC: gRPC cannot be
// forked once it runs, which is why children are forked up front and wait.
#pragma once

#include <sys/types.h>

#include <cstdio>
#include <functional>
#include <string>

namespace probecast::testing {

class ChildProcess {
 public:
  // Sends one line of text (no newline) to the parent.
  using Say = std::function<void(const std::string& line)>;
  // Waits for the parent's next line (tell()); false once the parent has closed its side or gone.
  using Hear = std::function<bool(std::string& line)>;
  // Forks now; the child runs `body` after go() and exits with its return value, or exits 0
  // without running it when the parent drops the child first.
  explicit ChildProcess(std::function<int(const Say& say)> body);
  // The same, for a child that also takes lines from the parent (a command loop).
  explicit ChildProcess(std::function<int(const Say& say, const Hear& hear)> body);
  ~ChildProcess();  // releases an unstarted child without running it, then waits for it
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  void go();
  // Sends one line (no newline) to a started child; false when it is gone.
  bool tell(const std::string& line);
  // The child's next line, of any length; false when it has ended without one.
  bool readLine(std::string& line);
  // Waits for the child to end; its exit status (-1 when it did not exit normally).
  int wait();
  // Sends the child a signal (SIGKILL: it dies as a crashed machine would); nothing once it has been waited for.
  void signal(int sig);

 private:
  void start(std::function<int(const Say& say, const Hear& hear)> body);
  bool writeToChild(const char* data, size_t size);

  pid_t pid_ = -1;
  int goFd_ = -1;  // the "go" byte, then the parent's lines
  FILE* from_ = nullptr;
};

}  // namespace probecast::testing
