#include "probecast/testing/nats_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

extern char** environ;

namespace probecast::testing {
int freeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket failed");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  const bool ok = bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  close(fd);
  if (!ok) throw std::runtime_error("no free loopback port");
  return ntohs(a.sin_port);
}

namespace {

bool accepts(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  close(fd);
  return ok;
}

std::string tail(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string all = ss.str();
  return all.size() > 800 ? all.substr(all.size() - 800) : all;
}

}  // namespace

std::string NatsServer::findProgram() {
  std::vector<std::string> dirs;
  if (const char* path = std::getenv("PATH")) {
    std::stringstream ss(path);
    for (std::string d; std::getline(ss, d, ':');)
      if (!d.empty()) dirs.push_back(d);
  }
  dirs.push_back("/usr/sbin");
  dirs.push_back("/usr/bin");
  for (const std::string& d : dirs) {
    const std::string p = d + "/nats-server";
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

NatsServer::NatsServer(const NatsServerOptions& options)
    : options_(options), program_(findProgram()), store_(options.storeDir) {
  if (program_.empty())
    throw std::runtime_error("nats-server not found on PATH, in /usr/sbin or /usr/bin (install it: scripts/setup.sh)");
  if (options.tlsCert.empty() != options.tlsKey.empty())
    throw std::invalid_argument("a nats-server's TLS needs both a certificate and a key");
  if (store_.empty()) {
    std::string pattern = (std::filesystem::temp_directory_path() / "probecast-nats-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot make a temporary folder for the NATS store");
    store_ = pattern;
    temporary_ = true;
  }
  std::random_device random;
  std::ostringstream token;
  for (int i = 0; i < 4; ++i) token << std::hex << std::setw(8) << std::setfill('0') << random();
  token_ = token.str();
  port_ = freeLoopbackPort();
  start();
}

service::BusConfig NatsServer::bus(const std::string& stream) const {
  service::BusConfig b;
  b.url = url();
  b.stream = stream;
  b.token = token_;
  b.tls = tls();
  b.caFile = options_.tlsCert;  // self-signed: the certificate is its own root
  b.plaintext = !tls();
  return b;
}

NatsServer::~NatsServer() {
  stop();
  if (temporary_) {
    std::error_code ec;
    std::filesystem::remove_all(store_, ec);
  }
}

std::string NatsServer::url() const { return "nats://127.0.0.1:" + std::to_string(port_); }

void NatsServer::start() {
  if (pid_ > 0) return;
  const std::string port = std::to_string(port_), log = store_ + "/nats-server.log";
  // Token and TLS in a configuration file of the owner's alone, not on the command line for all to see.
  const std::string conf = store_ + "/nats-server.conf";
  {
    std::ofstream out(conf, std::ios::trunc);
    out << "authorization { token: \"" << token_ << "\" }\n";
    if (tls()) out << "tls { cert_file: \"" << options_.tlsCert << "\"\n key_file: \"" << options_.tlsKey << "\" }\n";
    if (!out) throw std::runtime_error("cannot write " + conf);
  }
  std::filesystem::permissions(conf, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  std::vector<std::string> args = {program_, "-c", conf, "-a", "127.0.0.1", "-p", port, "-js", "-sd", store_, "-l", log};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  if (posix_spawn(&pid_, program_.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    pid_ = -1;
    throw std::runtime_error("cannot start " + program_);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!accepts(port_)) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("nats-server ended at start on port " + port + ": " + tail(log));
    }
    if (std::chrono::steady_clock::now() > deadline) {
      stop();
      throw std::runtime_error("nats-server did not accept connections on port " + port + " within 10 s: " + tail(log));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void NatsServer::stop() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  int status = 0;
  while (waitpid(pid_, &status, WNOHANG) != pid_) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  pid_ = -1;
}

}  // namespace probecast::testing
