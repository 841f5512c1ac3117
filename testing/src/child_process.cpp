#include "probecast/testing/child_process.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <stdexcept>

namespace probecast::testing {

ChildProcess::ChildProcess(std::function<int(const Say& say)> body) {
  start([body = std::move(body)](const Say& say, const Hear&) { return body(say); });
}

ChildProcess::ChildProcess(std::function<int(const Say& say, const Hear& hear)> body) { start(std::move(body)); }

void ChildProcess::start(std::function<int(const Say& say, const Hear& hear)> body) {
  int toChild[2], fromChild[2];
  if (pipe(toChild) != 0) throw std::runtime_error("pipe failed");
  if (pipe(fromChild) != 0) {
    close(toChild[0]);
    close(toChild[1]);
    throw std::runtime_error("pipe failed");
  }
  std::fflush(stdout);
  std::fflush(stderr);
  pid_ = fork();
  if (pid_ < 0) {
    for (int fd : {toChild[0], toChild[1], fromChild[0], fromChild[1]}) close(fd);
    throw std::runtime_error("fork failed");
  }
  if (pid_ == 0) {
    // Only its own pipes: a copy of another child's would keep that child from seeing its parent go.
    const long maxFd = std::min(sysconf(_SC_OPEN_MAX), 65536L);
    for (int fd = 3; fd < maxFd; ++fd)
      if (fd != toChild[0] && fd != fromChild[1]) close(fd);
    char go = 0;
    if (read(toChild[0], &go, 1) != 1) _exit(0);  // dropped before go()
    FILE* to = fdopen(fromChild[1], "w");
    const Say say = [to](const std::string& line) {
      std::fprintf(to, "%s\n", line.c_str());
      std::fflush(to);
    };
    FILE* from = fdopen(toChild[0], "r");
    const Hear hear = [from](std::string& line) {
      line.clear();
      for (int c; (c = std::fgetc(from)) != EOF;) {
        if (c == '\n') return true;
        line.push_back(static_cast<char>(c));
      }
      return false;  // a last line without its newline is a parent cut off mid-line: not a command
    };
    int status = 1;
    try {
      status = body(say, hear);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "probecast: error in a child process: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "probecast: unknown error in a child process\n");
    }
    std::fflush(nullptr);
    _exit(status);  // not exit(): the parent's state (and its atexit handlers) is not ours
  }
  close(toChild[0]);
  close(fromChild[1]);
  goFd_ = toChild[1];
  from_ = fdopen(fromChild[0], "r");
}

ChildProcess::~ChildProcess() {
  if (goFd_ >= 0) close(goFd_);
  if (from_) std::fclose(from_);
  wait();
}

bool ChildProcess::writeToChild(const char* data, size_t size) {
  // A child that is already gone must not take this process with it (SIGPIPE): ignore the signal
  // for the write and get EPIPE instead.
  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &previous);
  bool written = goFd_ >= 0;
  while (written && size > 0) {
    const ssize_t n = write(goFd_, data, size);
    if (n < 0 && errno == EINTR) continue;
    written = n > 0;
    if (written) {
      data += n;
      size -= static_cast<size_t>(n);
    }
  }
  sigaction(SIGPIPE, &previous, nullptr);
  return written;
}

void ChildProcess::go() {
  const char go = 1;
  if (!writeToChild(&go, 1)) throw std::runtime_error("child process is gone");
}

bool ChildProcess::tell(const std::string& line) {
  const std::string withNewline = line + "\n";
  return writeToChild(withNewline.data(), withNewline.size());
}

bool ChildProcess::readLine(std::string& line) {
  line.clear();
  if (!from_) return false;
  for (int c; (c = std::fgetc(from_)) != EOF;) {
    if (c == '\n') return true;
    line.push_back(static_cast<char>(c));
  }
  return !line.empty();
}

void ChildProcess::signal(int sig) {
  if (pid_ > 0) kill(pid_, sig);
}

int ChildProcess::wait() {
  if (pid_ <= 0) return -1;
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace probecast::testing
