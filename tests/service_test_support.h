// What the service tests share: a small volume, a producer thread, configurations, and bounded
// waits. Header-only; each test binary includes it once.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "probecast.grpc.pb.h"
#include "probecast/service/client.h"
#include "probecast/service/probe_hub.h"
#include "probecast/service/server.h"
#include "test_probes.h"

namespace probecast::service {

using namespace std::chrono_literals;

inline constexpr char kToken[] = "test-token";

inline HubConfig volumeConfig() {
  // 16 × 4 × 16 probes (the moving-light generator's layout), bricks of 4: 16 bricks.
  HubConfig c;
  c.layout.grid[0] = 16;
  c.layout.grid[1] = 4;
  c.layout.grid[2] = 16;
  c.layout.brickDim = 4;
  c.layout.repr = Representation::Zh3;
  c.bounds.min[0] = -2.0f;
  c.bounds.max[0] = 1.5f;
  c.bounds.max[1] = 1.5f;
  c.bounds.min[2] = -2.0f;
  c.bounds.max[2] = 5.5f;
  return c;
}

// Publishes `frames` moving-light frames, then keeps ticking until stopped.
class Producer {
 public:
  Producer(ProbeHub& hub, int frames, std::chrono::milliseconds interval) : hub_(hub) {
    thread_ = std::thread([this, frames, interval] {
      std::mt19937 rng(5);
      for (int f = 0; !stop_; ++f) {
        if (f < frames) hub_.publish(test::movingLightFrame(1024, f, 0.01f, rng).data(), nullptr);
        else hub_.tick();
        published_ = std::min(f + 1, frames);
        std::this_thread::sleep_for(f < frames ? interval : 10ms);
      }
    });
  }
  ~Producer() { stop(); }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  int published() const { return published_; }

 private:
  ProbeHub& hub_;
  std::atomic<bool> stop_{false};
  std::atomic<int> published_{0};
  std::thread thread_;
};

// A self-signed certificate for localhost and 127.0.0.1, made with openssl into `dir` as
// NAME-key.pem and NAME-cert.pem (its own root); false when openssl fails.
inline bool makeTestCertificate(const std::string& dir, const std::string& name, std::string& keyFile,
                                std::string& certFile) {
  keyFile = dir + "/" + name + "-key.pem";
  certFile = dir + "/" + name + "-cert.pem";
  const std::string cmd = "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
                          "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout " + keyFile + " -out " + certFile +
                          " >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

inline ServerConfig plaintextConfig() {
  ServerConfig c;
  c.listen = "127.0.0.1:0";
  c.token = kToken;
  c.plaintext = true;
  return c;
}

inline ClientConfig clientFor(int port, uint64_t budget = 0) {
  ClientConfig c;
  c.address = "127.0.0.1:" + std::to_string(port);
  c.token = kToken;
  c.budgetBytesPerSecond = budget;
  return c;
}

inline bool matchesServer(const ProbeClient& client, const ProbeHub& hub) {
  VolumeSnapshot snap;
  if (!client.snapshot(snap)) return false;
  const ProbeVolume server = hub.reconstruction();
  const std::vector<float>& probes = server.probes;
  return snap.volume.probes.size() == probes.size() &&
         std::memcmp(snap.volume.probes.data(), probes.data(), probes.size() * sizeof(float)) == 0 &&
         snap.volume.active == server.active;
}

template <typename Pred>
bool waitFor(Pred pred, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return pred();
}

inline View viewAt(float x, float z) {
  // A narrow orthographic view down −z around (x, 0.75), depth 0..40 m from an eye at z + 20.
  View v{};
  v.viewProj[0] = 1.0f;
  v.viewProj[5] = 1.0f;
  v.viewProj[10] = -1.0f / 40.0f;
  v.viewProj[12] = -x;
  v.viewProj[13] = -0.75f;
  v.viewProj[14] = (z + 20.0f) / 40.0f;
  v.viewProj[15] = 1.0f;
  v.eye[0] = x;
  v.eye[1] = 0.75f;
  v.eye[2] = z + 20.0f;
  return v;
}

// Sends `first` (and `second` if given), half-closes, and returns the stream's final status: for
// streams the server refuses (a valid subscriber's half-closed stream lasts until the deadline).
inline grpc::Status statusAfter(v1::ProbeStream::Stub& stub, const v1::ClientMessage& first,
                                const v1::ClientMessage* second = nullptr,
                                std::chrono::milliseconds deadline = std::chrono::seconds(5)) {
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + deadline);
  auto stream = stub.Subscribe(&ctx);
  stream->Write(first);
  if (second) stream->Write(*second);
  stream->WritesDone();
  v1::ServerMessage msg;
  while (stream->Read(&msg)) {
  }
  return stream->Finish();
}

}  // namespace probecast::service
