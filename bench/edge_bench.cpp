#include "edge_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "probecast/codec/stream.h"
#include "probecast/service/client.h"
#include "probecast/session/child_process.h"
#include "probecast/session/edge_process.h"
#include "probecast/session/nats_server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "stream_bench.h"

namespace probecast::bench {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
constexpr char kToken[] = "bench";

// The producer, in a process of its own: lighting frames at `hz` for `moving` seconds, then the
// same lighting for `hold` seconds (so every client can catch up); served directly and
// published to the bus. Says "port N", then "report MESSAGES BYTES KEYFRAME_BYTES DELTA_BYTES FRAMES".
int produce(const EdgeBenchOptions& o, const service::BusConfig& bus, double moving, double hold,
            const session::ChildProcess::Say& say) {
  session::ProbeProducer producer(service::hubConfigFor(
      session::unitGrid({kLightingGrid[0], kLightingGrid[1], kLightingGrid[2]}),
      parseRepresentation(o.repr).value_or(Representation::Zh3), 4, 1));
  service::ServerConfig sc;
  sc.plaintext = true;
  sc.token = kToken;
  say(fmt::format("port {}", producer.serve(sc)));
  producer.publishTo(bus);
  producer.generate([](uint32_t frame, std::vector<float>& probes) { lightingFrame(static_cast<int>(frame), probes); });
  session::Pacing pacing;
  pacing.mode = session::Pacing::Mode::FixedRate;
  pacing.hz = o.hz;
  pacing.seconds = moving + hold;
  producer.run(pacing, nullptr, [&](double seconds) { producer.setMoving(seconds < moving); });
  const service::PublisherStats st = producer.busStats();
  say(fmt::format("report {} {} {} {} {}", st.messages, st.bytes, st.keyframeBytes, st.deltaBytes,
                  producer.stats().updates));
  producer.shutdownServer();
  return 0;
}

std::vector<std::unique_ptr<service::ProbeClient>> startClients(int n, const std::function<std::vector<std::string>(int)>& servers) {
  std::vector<std::unique_ptr<service::ProbeClient>> clients;
  for (int i = 0; i < n; ++i) {
    service::ClientConfig cc;
    cc.addresses = servers(i);
    cc.token = kToken;
    cc.reconnectMaxMs = 200;
    clients.push_back(std::make_unique<service::ProbeClient>(cc));
    clients.back()->start();
  }
  return clients;
}

// Latencies (ms) of frames applied after `from` frames each (the joining keyframes left out).
std::vector<double> latenciesMs(const std::vector<std::unique_ptr<service::ProbeClient>>& clients) {
  std::vector<double> ms;
  for (const auto& c : clients)
    for (uint32_t us : c->latenciesUs()) ms.push_back(us / 1000.0);
  return ms;
}

bool sameVolume(const service::ProbeClient& a, const service::ProbeClient& b) {
  service::VolumeSnapshot x, y;
  if (!a.snapshot(x) || !b.snapshot(y)) return false;
  return x.volume.probes.size() == y.volume.probes.size() && x.volume.active == y.volume.active &&
         std::memcmp(x.volume.probes.data(), y.volume.probes.data(), x.volume.probes.size() * sizeof(float)) == 0;
}

std::string at(int port) { return "127.0.0.1:" + std::to_string(port); }

}  // namespace

EdgeBenchResult runEdgeBench(const EdgeBenchOptions& o) {
  if (o.clients < 1 || o.kills < 0 || o.seconds < 1.0) throw std::invalid_argument("bench edge: nonsense options");
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  session::NatsServer nats;
  const service::BusConfig bus = nats.bus("bench");
  const int ports[2] = {session::freeLoopbackPort(), session::freeLoopbackPort()};
  const double killSeconds = 1.5;
  const double moving = 2 * (o.seconds + 1.0) + o.kills * killSeconds + 2.0, hold = 4.0;
  // Every child forked now, before this process starts gRPC: the producer, the two edges and one
  // replacement per kill (on the port of the edge it replaces).
  session::ChildProcess producer(
      [&](const session::ChildProcess::Say& tell) { return produce(o, bus, moving, hold, tell); });
  std::vector<std::unique_ptr<session::EdgeProcess>> edges;
  for (int k = 0; k < 2 + o.kills; ++k) {
    service::EdgeConfig ec;
    ec.bus = bus;
    ec.server.listen = at(ports[k % 2]);
    ec.server.token = kToken;
    ec.server.plaintext = true;
    edges.push_back(std::make_unique<session::EdgeProcess>(ec));
  }
  producer.go();
  std::string line;
  int direct = 0;
  if (!producer.readLine(line) || std::sscanf(line.c_str(), "port %d", &direct) != 1)
    throw std::runtime_error("producer process did not start");
  edges[0]->start();
  edges[1]->start();
  say(fmt::format("producer on port {}, edges on {} and {}, NATS on {}", direct, ports[0], ports[1], nats.port()));
  const auto started = Clock::now();

  // Latency, direct and then through the edges (one phase at a time, so they share no CPU).
  auto directClients = startClients(o.clients, [&](int) { return std::vector<std::string>{at(direct)}; });
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds + 1.0));
  const std::vector<double> directMs = latenciesMs(directClients);
  auto edgeClients = startClients(o.clients, [&](int i) {
    return std::vector<std::string>{at(ports[i % 2]), at(ports[(i + 1) % 2])};
  });
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds + 1.0));
  const std::vector<double> edgeMs = latenciesMs(edgeClients);
  say(fmt::format("latency p50 direct {:.2f} ms, through NATS + edge {:.2f} ms", session::percentile(directMs, 0.5),
                  session::percentile(edgeMs, 0.5)));

  // Failover: kill the edge on one port, time its clients to the other; a fresh edge takes the port.
  std::vector<double> reconnectMs, firstFrameMs;
  for (int k = 0; k < o.kills; ++k) {
    const std::string dying = at(ports[k % 2]);
    std::vector<service::ProbeClient*> movers;
    std::vector<uint32_t> applied;
    for (auto& c : edgeClients)
      if (c->stats().address == dying) {
        movers.push_back(c.get());
        applied.push_back(c->stats().framesApplied);
      }
    const auto t0 = Clock::now();
    edges[k]->kill();
    std::vector<bool> reconnected(movers.size(), false), framed(movers.size(), false);
    size_t left = movers.size() * 2;
    while (left > 0 && Clock::now() - t0 < 10s) {
      for (size_t i = 0; i < movers.size(); ++i) {
        const service::ClientStats st = movers[i]->stats();
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        const bool elsewhere = st.connected && st.address != dying;
        if (!reconnected[i] && elsewhere) reconnected[i] = true, reconnectMs.push_back(ms), --left;
        if (!framed[i] && elsewhere && st.framesApplied > applied[i]) framed[i] = true, firstFrameMs.push_back(ms), --left;
      }
      std::this_thread::sleep_for(200us);
    }
    edges[2 + k]->start();
    say(fmt::format("kill {}: {} clients moved, first frame from the other edge after {:.1f} ms (median so far)", k + 1,
                    movers.size(), session::percentile(firstFrameMs, 0.5)));
    std::this_thread::sleep_for(std::chrono::duration<double>(killSeconds));
  }

  // The lighting holds still at the end: every client must reach the direct clients' volume.
  const auto holdAt = started + std::chrono::duration<double>(moving + 1.5);
  std::this_thread::sleep_until(holdAt);
  int identical = 0;
  for (auto& c : edgeClients) identical += sameVolume(*c, *directClients[0]) ? 1 : 0;
  int directIdentical = 0;
  for (auto& c : directClients) directIdentical += sameVolume(*c, *directClients[0]) ? 1 : 0;
  uint32_t rejected = 0, failovers = 0;
  for (auto& c : edgeClients) {
    rejected += c->stats().framesRejected;
    failovers += c->stats().failovers;
  }
  for (auto& c : directClients) c->stop();
  for (auto& c : edgeClients) c->stop();
  uint64_t messages = 0, bytes = 0, keyBytes = 0, deltaBytes = 0;
  int frames = 0;
  if (!producer.readLine(line) ||
      std::sscanf(line.c_str(), "report %lu %lu %lu %lu %d", &messages, &bytes, &keyBytes, &deltaBytes, &frames) != 5)
    throw std::runtime_error("producer process did not report");
  producer.wait();
  for (size_t k = o.kills; k < edges.size(); ++k) edges[k]->stop();

  const double p50d = session::percentile(directMs, 0.5), p99d = session::percentile(directMs, 0.99);
  const double p50e = session::percentile(edgeMs, 0.5), p99e = session::percentile(edgeMs, 0.99);
  EdgeBenchResult r;
  r.json = {{"command", o.command},
            {"codec_format_version", kFormatVersion},
            {"volume", "32x8x32 probes, bricks of 4, " + o.repr + ", dead-zone 1, light circling"},
            {"hz", o.hz},
            {"clients_per_phase", o.clients},
            {"seconds_per_phase", o.seconds},
            {"latency_ms", {{"direct_p50", p50d}, {"direct_p99", p99d}, {"edge_p50", p50e}, {"edge_p99", p99e},
                            {"added_p50", p50e - p50d}, {"added_p99", p99e - p99d},
                            {"direct_samples", directMs.size()}, {"edge_samples", edgeMs.size()}}},
            {"failover_ms", {{"kills", o.kills}, {"clients_moved", firstFrameMs.size()},
                             {"reconnected_median", session::percentile(reconnectMs, 0.5)},
                             {"first_frame_median", session::percentile(firstFrameMs, 0.5)},
                             {"first_frame_max", firstFrameMs.empty() ? 0.0 : *std::max_element(firstFrameMs.begin(), firstFrameMs.end())},
                             {"first_frame_samples", firstFrameMs}}},
            {"bit_identical", {{"edge_clients", o.clients}, {"identical_to_direct", identical},
                               {"direct_identical", directIdentical}, {"frames_rejected", rejected},
                               {"failovers", failovers}}},
            {"bus", {{"messages", messages}, {"bytes", bytes}, {"keyframe_bytes", keyBytes}, {"delta_bytes", deltaBytes},
                     {"frames", frames}}},
            {"notes", "loopback on one machine; producer, edges (SIGKILLed for failover) and nats-server in processes "
                      "of their own, clients in this one; latency = client decode time minus the producer's publish "
                      "time of the frame's lighting; failover = SIGKILL to the first frame applied from the other edge "
                      "(includes the wait for the next lighting update, up to 1/hz)"}};
  r.table = fmt::format(
      "latency ms     p50      p99\n  direct   {:8.2f} {:8.2f}\n  edge     {:8.2f} {:8.2f}\n  added    {:8.2f} {:8.2f}\n"
      "failover: {} clients over {} kills, reconnected after {:.1f} ms, first frame after {:.1f} ms (medians)\n"
      "bit-identical after failover: {}/{} edge clients; bus: {} messages, {:.0f} kB ({:.0f} kB keyframes, {:.0f} kB "
      "deltas) over {} frames\n",
      p50d, p99d, p50e, p99e, p50e - p50d, p99e - p99d, firstFrameMs.size(), o.kills,
      session::percentile(reconnectMs, 0.5), session::percentile(firstFrameMs, 0.5), identical, o.clients, messages,
      static_cast<double>(bytes) / 1e3, static_cast<double>(keyBytes) / 1e3, static_cast<double>(deltaBytes) / 1e3,
      frames);
  return r;
}

}  // namespace probecast::bench
