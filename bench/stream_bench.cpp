#include "stream_bench.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "harness.h"
#include "load_client.h"
#include "probecast/codec/stream.h"
#include "probecast/service/edge_server.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "probecast/testing/child_process.h"
#include "probecast/testing/nats_server.h"
#include "probecast/imaging/svg_chart.h"
#include "stream_parts.h"

namespace probecast::bench {

using namespace streaming;

namespace {

using namespace std::chrono_literals;

// The server side of a run: its processes (the producer first) and the addresses subscribers
// connect to; a relayed run also has a nats-server, whose CPU and memory count as the server's.
struct Topology {
  std::unique_ptr<testing::NatsServer> nats;
  std::vector<std::unique_ptr<testing::ChildProcess>> servers;
  std::vector<std::string> addresses;
};

// Starts a server-side child and reads the port it says.
int startServerChild(testing::ChildProcess& child, const std::string& who) {
  child.go();
  std::string line;
  int port = 0;
  if (!child.readLine(line) || std::sscanf(line.c_str(), "port %d", &port) != 1)
    throw std::runtime_error(who + " did not start: " + line);
  return port;
}

// One server, subscribers connected straight to it; or (o.edges > 0) the producer publishing to
// a nats-server with JetStream and that many edges serving the subscribers, split evenly.
Topology makeTopology(const StreamBenchOptions& o) {
  Topology t;
  service::BusConfig bus;
  if (o.edges > 0) {
    t.nats = std::make_unique<testing::NatsServer>();
    bus = t.nats->bus("bench");
  }
  const service::BusConfig* busOrNull = o.edges > 0 ? &bus : nullptr;
  t.servers.push_back(std::make_unique<testing::ChildProcess>(
      [&o, busOrNull](const testing::ChildProcess::Say& say, const testing::ChildProcess::Hear& hear) {
        return serveLightingFrames(o.hz, o.repr, o.grid, busOrNull, say, hear);
      }));
  const int port = startServerChild(*t.servers.back(), "server process");
  if (o.edges == 0) t.addresses.push_back("127.0.0.1:" + std::to_string(port));
  for (int e = 0; e < o.edges; ++e) {
    t.servers.push_back(std::make_unique<testing::ChildProcess>(
        [bus](const testing::ChildProcess::Say& say, const testing::ChildProcess::Hear& hear) {
          return serveEdge(bus, say, hear);
        }));
    t.addresses.push_back("127.0.0.1:" + std::to_string(startServerChild(*t.servers.back(), "edge process")));
  }
  return t;
}

ProcessSample sampleAll(std::vector<std::unique_ptr<testing::ChildProcess>>& processes, const std::string& who,
                        pid_t other = -1) {
  ProcessSample total = sampleProcess(other);
  for (auto& p : processes) {
    const ProcessSample s = parseSample(ask(*p, "sample", "sample", who), who);
    total.cpuSeconds += s.cpuSeconds;
    total.rssKb += s.rssKb;
  }
  return total;
}

service::LatencyHistogram takeWriteLatency(Topology& t) {
  service::LatencyHistogram all;
  for (auto& p : t.servers) {
    service::LatencyHistogram h;
    if (!service::LatencyHistogram::fromText(ask(*p, "latency", "latency", "server"), h))
      throw std::runtime_error("server sent a bad latency histogram");
    all.merge(h);
  }
  return all;
}

LoadReport takeAll(std::vector<std::unique_ptr<testing::ChildProcess>>& loads) {
  LoadReport total;
  for (auto& l : loads) {
    const LoadReport r = parseFigures(ask(*l, "take", "figures", "load process"), "load process");
    total.process.cpuSeconds += r.process.cpuSeconds;
    total.process.rssKb += r.process.rssKb;
    LoadFigures& f = total.figures;
    f.frames += r.figures.frames;
    f.bytes += r.figures.bytes;
    f.sequenceErrors += r.figures.sequenceErrors;
    f.crcErrors += r.figures.crcErrors;
    f.decodeErrors += r.figures.decodeErrors;
    f.streamErrors += r.figures.streamErrors;
    f.latency.merge(r.figures.latency);
    if (!r.figures.lastError.empty()) f.lastError = r.figures.lastError;
  }
  return total;
}

void checkStreamBenchOptions(const StreamBenchOptions& o) {
  for (int n : o.subscribers)
    if (n < 1) throw std::invalid_argument("subscriber counts must be positive");
  if (o.subscribersPerLoadProcess < 1 || o.sampleEvery < 1 || o.ackIntervalMs < 0)
    throw std::invalid_argument(
        "subscribers per load process and the sampling interval must be positive, the ack interval not negative");
  if (!isValidLayout(streamLayoutFor(session::unitGrid({o.grid[0], o.grid[1], o.grid[2]}), Representation::Zh3, 4)))
    throw std::invalid_argument(fmt::format("a {}x{}x{} grid cannot be streamed (too many probes for the stream format)",
                                            o.grid[0], o.grid[1], o.grid[2]));
}

ProcessSample sampleServers(Topology& topo) {
  return sampleAll(topo.servers, "server", topo.nats ? topo.nats->pid() : -1);
}

// Load: separate processes, a share of the `n` subscribers each. Returns once each has said how
// many of its subscribers connected.
std::vector<std::unique_ptr<testing::ChildProcess>> startLoads(const StreamBenchOptions& o, const Topology& topo, int n,
                                                               SubscriberRun& run) {
  run.loadProcesses = (n + o.subscribersPerLoadProcess - 1) / o.subscribersPerLoadProcess;
  const int processes = run.loadProcesses;
  std::vector<std::unique_ptr<testing::ChildProcess>> loads;
  for (int k = 0; k < processes; ++k) {
    LoadClientConfig lc;
    lc.addresses = topo.addresses;
    lc.token = kBenchToken;
    lc.firstIndex = static_cast<uint32_t>(static_cast<int64_t>(n) * k / processes);
    lc.subscribers = static_cast<uint32_t>(static_cast<int64_t>(n) * (k + 1) / processes) - lc.firstIndex;
    lc.sampleEvery = static_cast<uint32_t>(o.sampleEvery);
    lc.ackIntervalMs = static_cast<uint32_t>(o.ackIntervalMs);
    lc.linkPacing = o.linkPacing;
    lc.budgetBytesPerSecond = o.budgetBytesPerSecond;
    lc.view = [dims = o.grid](uint32_t i) { return randomView(i, dims); };
    loads.push_back(std::make_unique<testing::ChildProcess>(
        [lc](const testing::ChildProcess::Say& s, const testing::ChildProcess::Hear& h) { return runLoad(lc, s, h); }));
    loads.back()->go();
  }
  for (auto& l : loads) {
    std::string line;
    unsigned c = 0;
    if (!l->readLine(line) || std::sscanf(line.c_str(), "connected %u", &c) != 1)
      throw std::runtime_error("load process did not start: " + line);
    run.connected += c;
  }
  return loads;
}

// The lighting stops; every decoding subscriber must come to hold the producer's volume. Then
// every process is told to quit.
void finishRun(Topology& topo, std::vector<std::unique_ptr<testing::ChildProcess>>& loads, SubscriberRun& run) {
  std::string hash;
  {
    const std::string fin = ask(*topo.servers[0], "stop", "final", "server");
    char h[32] = {};
    if (std::sscanf(fin.c_str(), "%31s %u %lf", h, &run.published, &run.encodeMs) != 3)
      throw std::runtime_error("server sent a bad final line: " + fin);
    hash = h;
  }
  for (auto& l : loads) {
    unsigned sampled = 0, identical = 0;
    const std::string r = ask(*l, "check " + hash, "samples", "load process");
    if (std::sscanf(r.c_str(), "%u %u", &sampled, &identical) != 2) throw std::runtime_error("bad sample check: " + r);
    run.samples.sampled += sampled;
    run.samples.identical += identical;
  }
  for (auto& l : loads) {
    l->tell("quit");
    l->wait();
  }
  for (auto& sv : topo.servers) {
    sv->tell("quit");
    sv->wait();
  }
}

SubscriberRun measureSubscribers(const StreamBenchOptions& o, int n) {
  const auto say = [&](const std::string& line) { sayProgress(o.progress, line); };
  SubscriberRun run;
  run.subscribers = n;
  Topology topo = makeTopology(o);
  say(fmt::format("{} subscribers on {}{}, {:.0f} s at {} Hz", n, topo.addresses[0],
                  o.edges > 0 ? fmt::format(" and {} more edges (through NATS)", o.edges - 1) : "", o.seconds, o.hz));
  // Baseline: the producer publishing to nobody.
  const ProcessSample b0 = sampleServers(topo);
  auto tb = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(1500ms);
  run.baseline = sampleServers(topo);
  run.baselineCores = (run.baseline.cpuSeconds - b0.cpuSeconds) / secondsSince(tb);
  std::vector<std::unique_ptr<testing::ChildProcess>> loads = startLoads(o, topo, n, run);
  if (run.connected == 0) throw std::runtime_error("subscribers never connected to " + topo.addresses[0]);
  if (run.connected < static_cast<uint32_t>(n)) say(fmt::format("only {} of {} subscribers connected", run.connected, n));
  std::this_thread::sleep_for(1s);  // the first keyframes go out
  takeAll(loads);
  takeWriteLatency(topo);
  run.server0 = sampleServers(topo);
  const auto t0 = std::chrono::steady_clock::now();
  run.load0 = takeAll(loads);
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds));
  run.load1 = takeAll(loads);
  run.seconds = secondsSince(t0);
  run.server1 = sampleServers(topo);
  run.writes = takeWriteLatency(topo);
  finishRun(topo, loads, run);
  return run;
}

}  // namespace

StreamBenchResult runStreamBench(const StreamBenchOptions& o) {
  checkStreamBenchOptions(o);
  std::vector<SubscriberRun> runs;
  for (const int n : o.subscribers) runs.push_back(measureSubscribers(o, n));
  StreamBenchResult r;
  r.json = streamJson(o, runs);
  r.table = fmt::format("{:>6} {:>9} {:>8} {:>8} {:>8} {:>9} {:>9} {:>8} {:>10} {:>8} {:>9} {:>10} {:>8} {:>7}\n",
                        "subs", "frm/s/sub", "p50 ms", "p99 ms", "max ms", "wr p50", "wr p99", "srv cpu", "cpu/sub",
                        "rss MB", "KB/sub", "B/s/sub", "load cpu", "errors");
  for (const SubscriberRun& run : runs) {
    r.table += tableRow(run);
    r.failure += runFailures(run);
  }
  r.svg = streamChart(o, runs);
  return r;
}

}  // namespace probecast::bench
