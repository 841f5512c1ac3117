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
#include "probecast/session/probe_producer.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "probecast/testing/child_process.h"
#include "probecast/testing/edge_process.h"
#include "probecast/testing/nats_server.h"
#include "harness.h"
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
            const testing::ChildProcess::Say& say) {
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

using Clients = std::vector<std::unique_ptr<service::ProbeClient>>;
constexpr double kKillSeconds = 1.5;

// The processes of a run, every one forked at construction, before this process starts gRPC: the
// producer, the two edges and one replacement per kill (on the port of the edge it replaces), and
// the nats-server between them.
struct EdgeRig {
  explicit EdgeRig(const EdgeBenchOptions& o)
      : bus(nats.bus("bench")),
        moving(2 * (o.seconds + 1.0) + o.kills * kKillSeconds + 2.0),
        producer([this, &o](const testing::ChildProcess::Say& tell) { return produce(o, bus, moving, hold, tell); }) {
    for (int k = 0; k < 2 + o.kills; ++k) {
      service::EdgeConfig ec;
      ec.bus = bus;
      ec.server.listen = at(ports[k % 2]);
      ec.server.token = kToken;
      ec.server.plaintext = true;
      edges.push_back(std::make_unique<testing::EdgeProcess>(ec));
    }
  }
  EdgeRig(const EdgeRig&) = delete;
  EdgeRig& operator=(const EdgeRig&) = delete;

  // Starts the producer and the first two edges; returns the producer's own port.
  int start() {
    producer.go();
    std::string line;
    int direct = 0;
    if (!producer.readLine(line) || std::sscanf(line.c_str(), "port %d", &direct) != 1)
      throw std::runtime_error("producer process did not start");
    edges[0]->start();
    edges[1]->start();
    return direct;
  }

  testing::NatsServer nats;
  const service::BusConfig bus;
  const int ports[2] = {testing::freeLoopbackPort(), testing::freeLoopbackPort()};
  const double moving, hold = 4.0;  // seconds of moving lighting, then of the same lighting
  testing::ChildProcess producer;
  std::vector<std::unique_ptr<testing::EdgeProcess>> edges;
};

// What the bench measures: filled by the phases below, written by edgeJson and edgeTable.
struct EdgeMetrics {
  std::vector<double> directMs, edgeMs;           // produce → decoded latencies
  std::vector<double> reconnectMs, firstFrameMs;  // from each kill, per client moved
  int identical = 0, directIdentical = 0;         // clients holding the first direct client's volume
  uint32_t rejected = 0, failovers = 0;           // over the edge clients
  uint64_t messages = 0, bytes = 0, keyBytes = 0, deltaBytes = 0;  // on the bus
  int frames = 0;
};

// Failover: kill the edge on one port, time its clients to the other; a fresh edge takes the port.
void measureKill(const EdgeBenchOptions& o, EdgeRig& rig, const Clients& edgeClients, int k, EdgeMetrics& m) {
  const std::string dying = at(rig.ports[k % 2]);
  std::vector<service::ProbeClient*> movers;
  std::vector<uint32_t> applied;
  for (auto& c : edgeClients)
    if (c->stats().address == dying) {
      movers.push_back(c.get());
      applied.push_back(c->stats().framesApplied);
    }
  const auto t0 = Clock::now();
  rig.edges[k]->kill();
  std::vector<bool> reconnected(movers.size(), false), framed(movers.size(), false);
  size_t left = movers.size() * 2;
  while (left > 0 && Clock::now() - t0 < 10s) {
    for (size_t i = 0; i < movers.size(); ++i) {
      const service::ClientStats st = movers[i]->stats();
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      const bool elsewhere = st.connected && st.address != dying;
      if (!reconnected[i] && elsewhere) reconnected[i] = true, m.reconnectMs.push_back(ms), --left;
      if (!framed[i] && elsewhere && st.framesApplied > applied[i]) framed[i] = true, m.firstFrameMs.push_back(ms), --left;
    }
    std::this_thread::sleep_for(200us);
  }
  rig.edges[2 + k]->start();
  sayProgress(o.progress, fmt::format("kill {}: {} clients moved, first frame from the other edge after {:.1f} ms "
                                      "(median so far)",
                                      k + 1, movers.size(), session::percentile(m.firstFrameMs, 0.5)));
  std::this_thread::sleep_for(std::chrono::duration<double>(kKillSeconds));
}

// The lighting holds still at the end: every client must reach the direct clients' volume. Then
// the clients stop and the producer reports what it put on the bus.
void finishRun(const EdgeBenchOptions& o, EdgeRig& rig, Clients& directClients, Clients& edgeClients, EdgeMetrics& m) {
  for (auto& c : edgeClients) m.identical += sameVolume(*c, *directClients[0]) ? 1 : 0;
  for (auto& c : directClients) m.directIdentical += sameVolume(*c, *directClients[0]) ? 1 : 0;
  for (auto& c : edgeClients) {
    m.rejected += c->stats().framesRejected;
    m.failovers += c->stats().failovers;
  }
  for (auto& c : directClients) c->stop();
  for (auto& c : edgeClients) c->stop();
  std::string line;
  if (!rig.producer.readLine(line) || std::sscanf(line.c_str(), "report %lu %lu %lu %lu %d", &m.messages, &m.bytes,
                                                    &m.keyBytes, &m.deltaBytes, &m.frames) != 5)
    throw std::runtime_error("producer process did not report");
  rig.producer.wait();
  for (size_t k = o.kills; k < rig.edges.size(); ++k) rig.edges[k]->stop();
}

nlohmann::json edgeJson(const EdgeBenchOptions& o, const EdgeMetrics& m) {
  const double p50d = session::percentile(m.directMs, 0.5), p99d = session::percentile(m.directMs, 0.99);
  const double p50e = session::percentile(m.edgeMs, 0.5), p99e = session::percentile(m.edgeMs, 0.99);
  return {{"command", o.command},
          {"codec_format_version", kFormatVersion},
          {"volume", "32x8x32 probes, bricks of 4, " + o.repr + ", dead-zone 1, light circling"},
          {"hz", o.hz},
          {"clients_per_phase", o.clients},
          {"seconds_per_phase", o.seconds},
          {"latency_ms", {{"direct_p50", p50d}, {"direct_p99", p99d}, {"edge_p50", p50e}, {"edge_p99", p99e},
                          {"added_p50", p50e - p50d}, {"added_p99", p99e - p99d},
                          {"direct_samples", m.directMs.size()}, {"edge_samples", m.edgeMs.size()}}},
          {"failover_ms", {{"kills", o.kills}, {"clients_moved", m.firstFrameMs.size()},
                           {"reconnected_median", session::percentile(m.reconnectMs, 0.5)},
                           {"first_frame_median", session::percentile(m.firstFrameMs, 0.5)},
                           {"first_frame_max", m.firstFrameMs.empty() ? 0.0 : *std::max_element(m.firstFrameMs.begin(), m.firstFrameMs.end())},
                           {"first_frame_samples", m.firstFrameMs}}},
          {"bit_identical", {{"edge_clients", o.clients}, {"identical_to_direct", m.identical},
                             {"direct_identical", m.directIdentical}, {"frames_rejected", m.rejected},
                             {"failovers", m.failovers}}},
          {"bus", {{"messages", m.messages}, {"bytes", m.bytes}, {"keyframe_bytes", m.keyBytes},
                   {"delta_bytes", m.deltaBytes}, {"frames", m.frames}}},
          {"notes", "loopback on one machine; producer, edges (SIGKILLed for failover) and nats-server in processes "
                    "of their own, clients in this one; latency = client decode time minus the producer's publish "
                    "time of the frame's lighting; failover = SIGKILL to the first frame applied from the other edge "
                    "(includes the wait for the next lighting update, up to 1/hz)"}};
}

std::string edgeTable(const EdgeBenchOptions& o, const EdgeMetrics& m) {
  const double p50d = session::percentile(m.directMs, 0.5), p99d = session::percentile(m.directMs, 0.99);
  const double p50e = session::percentile(m.edgeMs, 0.5), p99e = session::percentile(m.edgeMs, 0.99);
  return fmt::format(
      "latency ms     p50      p99\n  direct   {:8.2f} {:8.2f}\n  edge     {:8.2f} {:8.2f}\n  added    {:8.2f} {:8.2f}\n"
      "failover: {} clients over {} kills, reconnected after {:.1f} ms, first frame after {:.1f} ms (medians)\n"
      "bit-identical after failover: {}/{} edge clients; bus: {} messages, {:.0f} kB ({:.0f} kB keyframes, {:.0f} kB "
      "deltas) over {} frames\n",
      p50d, p99d, p50e, p99e, p50e - p50d, p99e - p99d, m.firstFrameMs.size(), o.kills,
      session::percentile(m.reconnectMs, 0.5), session::percentile(m.firstFrameMs, 0.5), m.identical, o.clients,
      m.messages, static_cast<double>(m.bytes) / 1e3, static_cast<double>(m.keyBytes) / 1e3,
      static_cast<double>(m.deltaBytes) / 1e3, m.frames);
}

}  // namespace

EdgeBenchResult runEdgeBench(const EdgeBenchOptions& o) {
  if (o.clients < 1 || o.kills < 0 || o.seconds < 1.0) throw std::invalid_argument("bench edge: nonsense options");
  EdgeRig rig(o);
  const int direct = rig.start();
  sayProgress(o.progress, fmt::format("producer on port {}, edges on {} and {}, NATS on {}", direct, rig.ports[0],
                                      rig.ports[1], rig.nats.port()));
  const auto started = Clock::now();
  EdgeMetrics m;
  // Latency, direct and then through the edges (one phase at a time, so they share no CPU).
  Clients directClients = startClients(o.clients, [&](int) { return std::vector<std::string>{at(direct)}; });
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds + 1.0));
  m.directMs = latenciesMs(directClients);
  Clients edgeClients = startClients(o.clients, [&](int i) {
    return std::vector<std::string>{at(rig.ports[i % 2]), at(rig.ports[(i + 1) % 2])};
  });
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds + 1.0));
  m.edgeMs = latenciesMs(edgeClients);
  sayProgress(o.progress, fmt::format("latency p50 direct {:.2f} ms, through NATS + edge {:.2f} ms",
                                      session::percentile(m.directMs, 0.5), session::percentile(m.edgeMs, 0.5)));
  for (int k = 0; k < o.kills; ++k) measureKill(o, rig, edgeClients, k, m);
  std::this_thread::sleep_until(started + std::chrono::duration<double>(rig.moving + 1.5));
  finishRun(o, rig, directClients, edgeClients, m);
  return {edgeJson(o, m), edgeTable(o, m)};
}

}  // namespace probecast::bench
