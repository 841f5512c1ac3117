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

namespace probecast::bench {
namespace {

using namespace std::chrono_literals;
constexpr const char* kBenchToken = "bench";  // the server requires one; loopback only

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

}  // namespace

void lightingFrame(int frame, std::vector<float>& probes, std::array<uint16_t, 3> dims) {
  const int nx = dims[0], ny = dims[1], nz = dims[2];
  probes.assign(static_cast<size_t>(nx) * ny * nz * 27, 0.0f);
  const float a = 0.05f * static_cast<float>(frame);
  // Over the 32-wide grid: a circle of radius 10 around (16, 10, 16).
  const float cx = 0.5f * static_cast<float>(nx), cz = 0.5f * static_cast<float>(nz);
  const float r = 10.0f * static_cast<float>(nx) / 32.0f;
  const float light[3] = {cx + r * std::cos(a), 10.0f, cz + r * std::sin(a)};
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        float* p = &probes[((static_cast<size_t>(z) * ny + y) * nx + x) * 27];
        float d[3] = {light[0] - static_cast<float>(x), light[1] - static_cast<float>(y), light[2] - static_cast<float>(z)};
        const float d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 1.0f;
        const float inv = 1.0f / std::sqrt(d2);
        for (float& v : d) v *= inv;
        const float e = 400.0f / d2;
        const float basis[9] = {0.282095f, 0.488603f * d[1], 0.488603f * d[2], 0.488603f * d[0],
                                1.092548f * d[0] * d[1], 1.092548f * d[1] * d[2], 0.315392f * (3 * d[2] * d[2] - 1),
                                1.092548f * d[0] * d[2], 0.546274f * (d[0] * d[0] - d[1] * d[1])};
        const float rgb[3] = {1.0f, 0.85f, 0.7f};
        for (int i = 0; i < 9; ++i)
          for (int c = 0; c < 3; ++c) p[i * 3 + c] = (i == 0 ? 0.3f : 0.0f) + e * rgb[c] * basis[i] * (i < 4 ? 0.8f : 0.4f);
      }
}

namespace {

// What the server side of a run is made of; the direct topology is one server process, and a
// relayed one (an origin, a message bus, edges) adds processes whose CPU and memory count too.
struct ProcessSample {
  double cpuSeconds = 0;
  double rssKb = 0;
};

uint64_t rssKb() {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  uint64_t kb = 0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "VmRSS: %" SCNu64, &kb) == 1) break;
  std::fclose(f);
  return kb;
}

std::string sampleLine() { return fmt::format("sample {:.6f} {}", cpuSeconds(), rssKb()); }

// A child's answer to `command`: its next line, which must start with `expect`; the rest of it.
std::string ask(testing::ChildProcess& child, const std::string& command, const std::string& expect,
                const std::string& who) {
  std::string line;
  if (!child.tell(command) || !child.readLine(line))
    throw std::runtime_error(who + " ended before answering '" + command + "'");
  if (line.rfind(expect + " ", 0) != 0 && line != expect)
    throw std::runtime_error(who + " answered '" + command + "' with '" + line.substr(0, 200) + "'");
  return line.size() > expect.size() ? line.substr(expect.size() + 1) : std::string();
}

ProcessSample parseSample(const std::string& text, const std::string& who) {
  ProcessSample s;
  if (std::sscanf(text.c_str(), "%lf %lf", &s.cpuSeconds, &s.rssKb) != 2)
    throw std::runtime_error(who + " sent a bad sample: " + text);
  return s;
}

// The server process: a producer of lighting frames at `hz`, served over gRPC, driven by the
// parent's commands (sample, latency, stop, quit) so that baseline and load are measured apart.
// With `bus`, it also publishes every brick version there (the relayed topology's origin).
int serveLightingFrames(double hz, const std::string& repr, std::array<uint16_t, 3> dims, const service::BusConfig* bus,
                        const testing::ChildProcess::Say& say, const testing::ChildProcess::Hear& hear) {
  session::ProbeProducer producer(service::hubConfigFor(
      session::unitGrid({dims[0], dims[1], dims[2]}), parseRepresentation(repr).value_or(Representation::Zh3), 4, 1));
  service::ServerConfig sc;
  sc.plaintext = true;
  sc.token = kBenchToken;
  sc.maxSubscribers = 100000;
  say(fmt::format("port {}", producer.serve(sc)));
  if (bus) producer.publishTo(*bus);
  producer.generate([dims](uint32_t frame, std::vector<float>& probes) {
    lightingFrame(static_cast<int>(frame), probes, dims);
  });
  session::Pacing pacing;
  pacing.mode = session::Pacing::Mode::FixedRate;
  pacing.hz = hz;
  producer.start(pacing, [&say](const std::string& error) { say("error " + error); });
  for (std::string command; hear(command);) {
    if (command == "sample") {
      say(sampleLine());
    } else if (command == "latency") {
      say("latency " + producer.server()->takeFrameWriteLatency().toText());
    } else if (command == "stop") {  // the lighting holds still: subscribers converge to it
      producer.stop();
      const ProbeVolume v = producer.hub().reconstruction();
      const session::ProducerStats st = producer.stats();
      say(fmt::format("final {} {} {:.6f}", volumeHash(v.probes.data(), v.active.data(), v.count()), st.updates,
                      st.publishMs / std::max<double>(st.updates, 1)));
    } else if (command == "quit") {
      producer.stop();
      producer.shutdownServer();
      return 0;
    } else {
      say("unknown command " + command);
    }
  }
  return 1;  // the parent went away
}

struct LoadReport {
  ProcessSample process;
  LoadFigures figures;
};

// A load process: `config`'s subscribers, driven by the parent's commands (take, check, quit).
int runLoad(const LoadClientConfig& config, const testing::ChildProcess::Say& say,
            const testing::ChildProcess::Hear& hear) {
  LoadClient load(config);
  load.start();
  say(fmt::format("connected {}", load.waitConnected(std::chrono::seconds(20))));
  for (std::string command; hear(command);) {
    if (command == "take") {
      const LoadFigures f = load.take();
      say(fmt::format("figures {:.6f} {} {} {} {} {} {} {} | {} | {}", cpuSeconds(), rssKb(), f.frames, f.bytes,
                      f.sequenceErrors, f.crcErrors, f.decodeErrors, f.streamErrors, f.latency.toText(),
                      f.lastError));
    } else if (command.rfind("check ", 0) == 0) {
      const SampleCheck c = load.checkSamples(std::stoull(command.substr(6)), std::chrono::seconds(10));
      say(fmt::format("samples {} {}", c.sampled, c.identical));
    } else if (command == "quit") {
      load.stop();
      return 0;
    } else {
      say("unknown command " + command);
    }
  }
  return 1;
}

LoadReport parseFigures(const std::string& text, const std::string& who) {
  LoadReport r;
  LoadFigures& f = r.figures;
  const size_t bar1 = text.find(" | "), bar2 = bar1 == std::string::npos ? bar1 : text.find(" | ", bar1 + 3);
  unsigned long long n[6];
  if (bar2 == std::string::npos ||
      std::sscanf(text.c_str(), "%lf %lf %llu %llu %llu %llu %llu %llu", &r.process.cpuSeconds, &r.process.rssKb,
                  &n[0], &n[1], &n[2], &n[3], &n[4], &n[5]) != 8 ||
      !service::LatencyHistogram::fromText(text.substr(bar1 + 3, bar2 - bar1 - 3), f.latency))
    throw std::runtime_error(who + " sent bad figures: " + text.substr(0, 200));
  f.frames = n[0];
  f.bytes = n[1];
  f.sequenceErrors = n[2];
  f.crcErrors = n[3];
  f.decodeErrors = n[4];
  f.streamErrors = n[5];
  f.lastError = text.substr(bar2 + 3);
  return r;
}

// A top-down orthographic view of an 8 m patch from 20 m up, centred somewhere over the grid
// (`dims`, 1 m apart): clip x = (x − cx)/4, clip y = (z − cz)/4, clip z = (20 − y)/30
// (column-major, m[col * 4 + row]).
View randomView(uint32_t index, std::array<uint16_t, 3> dims) {
  std::mt19937 rng(7 + index);
  std::uniform_real_distribution<float> ux(0.0f, static_cast<float>(dims[0] - 1));
  std::uniform_real_distribution<float> uz(0.0f, static_cast<float>(dims[2] - 1));
  const float cx = ux(rng), cz = uz(rng), h = 4.0f;
  View v{};
  v.viewProj[0] = 1.0f / h;
  v.viewProj[12] = -cx / h;
  v.viewProj[9] = 1.0f / h;
  v.viewProj[13] = -cz / h;
  v.viewProj[6] = -1.0f / 30.0f;
  v.viewProj[14] = 20.0f / 30.0f;
  v.viewProj[15] = 1.0f;
  v.eye[0] = cx;
  v.eye[1] = 20.0f;
  v.eye[2] = cz;
  return v;
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// An edge process: an edge server fed from `bus`, driven like the server process (sample,
// latency, quit). It says its port once the bus has delivered the volume, so subscribers that
// connect then are served rather than told to go elsewhere.
int serveEdge(const service::BusConfig& bus, const testing::ChildProcess::Say& say,
              const testing::ChildProcess::Hear& hear) {
  service::EdgeConfig ec;
  ec.bus = bus;
  ec.server.plaintext = true;
  ec.server.token = kBenchToken;
  ec.server.maxSubscribers = 100000;
  service::EdgeServer edge(ec);
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (edge.stats().applied == 0 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(20ms);
  if (edge.stats().applied == 0) {
    say("error the edge received nothing from the bus: " + edge.stats().lastError);
    return 1;
  }
  say(fmt::format("port {}", edge.port()));
  for (std::string command; hear(command);) {
    if (command == "sample") {
      say(sampleLine());
    } else if (command == "latency") {
      say("latency " + edge.takeFrameWriteLatency().toText());
    } else if (command == "quit") {
      edge.shutdown();
      return 0;
    } else {
      say("unknown command " + command);
    }
  }
  return 1;
}

// CPU seconds and resident kB of another process (nats-server), from /proc.
ProcessSample sampleProcess(pid_t pid) {
  ProcessSample s;
  if (pid <= 0) return s;
  if (FILE* f = std::fopen(fmt::format("/proc/{}/stat", pid).c_str(), "r")) {
    char buf[1024];
    const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    buf[n] = 0;
    const char* p = std::strrchr(buf, ')');  // fields after the command name, which may hold spaces
    unsigned long long utime = 0, stime = 0;
    if (p && std::sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &utime, &stime) == 2)
      s.cpuSeconds = static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
  }
  if (FILE* f = std::fopen(fmt::format("/proc/{}/status", pid).c_str(), "r")) {
    char line[256];
    uint64_t kb = 0;
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "VmRSS: %" SCNu64, &kb) == 1) break;
    std::fclose(f);
    s.rssKb = static_cast<double>(kb);
  }
  return s;
}

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

// One subscriber count: what the server, the load and the check at the end measured.
struct SubscriberRun {
  int subscribers = 0;
  uint32_t connected = 0;
  int loadProcesses = 0;
  double seconds = 0;             // the measured window
  double baselineCores = 0;       // the server publishing to nobody
  ProcessSample baseline;         // the server at the baseline's end
  ProcessSample server0, server1;  // the server at the window's start and end
  LoadReport load0, load1;        // the load clients at the window's start and end
  service::LatencyHistogram writes;
  double encodeMs = 0;            // per published frame
  uint32_t published = 0;
  SampleCheck samples;            // decoding subscribers holding the producer's volume

  double serverCores() const { return (server1.cpuSeconds - server0.cpuSeconds) / seconds; }
  double corePerSub() const { return (serverCores() - baselineCores) / subscribers; }
  double rssKbPerSub() const { return (server1.rssKb - baseline.rssKb) / subscribers; }
  double bytesPerSub() const { return static_cast<double>(load1.figures.bytes) / seconds / subscribers; }
  double framesPerSub() const { return static_cast<double>(load1.figures.frames) / seconds / subscribers; }
  double loadCores() const { return (load1.process.cpuSeconds - load0.process.cpuSeconds) / seconds; }
  bool identical() const { return samples.sampled > 0 && samples.identical == samples.sampled; }
  uint64_t errors() const {
    const LoadFigures& f = load1.figures;
    return f.sequenceErrors + f.crcErrors + f.decodeErrors + f.streamErrors;
  }
};

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

nlohmann::json runJson(const StreamBenchOptions& o, const SubscriberRun& run) {
  const LoadFigures& f = run.load1.figures;
  return {{"subscribers", run.subscribers},
          {"topology", o.edges > 0 ? "nats" : "direct"},
          {"edges", o.edges},
          {"connected", run.connected},
          {"hz", o.hz},
          {"seconds", run.seconds},
          {"frames_received", f.frames},
          {"frames_per_subscriber_per_s", run.framesPerSub()},
          {"produce_to_receive_ms_p50", f.latency.percentileMs(0.5)},
          {"produce_to_receive_ms_p99", f.latency.percentileMs(0.99)},
          {"produce_to_receive_ms_max", static_cast<double>(f.latency.maxUs()) / 1000.0},
          {"publish_to_write_ms_p50", run.writes.percentileMs(0.5)},
          {"publish_to_write_ms_p99", run.writes.percentileMs(0.99)},
          {"frames_written", run.writes.count()},
          {"server_cpu_cores", run.serverCores()},
          {"server_cpu_cores_baseline", run.baselineCores},
          {"server_cpu_core_per_subscriber", run.corePerSub()},
          {"server_rss_mb", run.server1.rssKb / 1024.0},
          {"server_rss_mb_baseline", run.baseline.rssKb / 1024.0},
          {"rss_kb_per_subscriber", run.rssKbPerSub()},
          {"bytes_per_subscriber_per_s", run.bytesPerSub()},
          {"load_client_cpu_cores", run.loadCores()},
          {"load_processes", run.loadProcesses},
          {"encode_ms_per_frame", run.encodeMs},
          {"frames_published", run.published},
          {"sequence_errors", f.sequenceErrors},
          {"crc_errors", f.crcErrors},
          {"decode_errors", f.decodeErrors},
          {"stream_errors", f.streamErrors},
          {"sampled_subscribers", run.samples.sampled},
          {"sample_bit_identical", run.identical()}};
}

std::string tableRow(const SubscriberRun& run) {
  const LoadFigures& f = run.load1.figures;
  return fmt::format(
      "{:>6} {:>9.1f} {:>8.2f} {:>8.2f} {:>8.2f} {:>9.2f} {:>9.2f} {:>8.3f} {:>10.5f} {:>8.1f} {:>9.1f} {:>10.0f} "
      "{:>8.3f} {:>7}\n",
      run.subscribers, run.framesPerSub(), f.latency.percentileMs(0.5), f.latency.percentileMs(0.99),
      static_cast<double>(f.latency.maxUs()) / 1000.0, run.writes.percentileMs(0.5), run.writes.percentileMs(0.99),
      run.serverCores(), run.corePerSub(), run.server1.rssKb / 1024.0, run.rssKbPerSub(), run.bytesPerSub(),
      run.loadCores(), run.errors());
}

// What went wrong in a run (empty: nothing).
std::string runFailures(const SubscriberRun& run) {
  const LoadFigures& f = run.load1.figures;
  const int n = run.subscribers;
  std::string failure;
  if (!run.identical())
    failure += fmt::format("{} subscribers: {} of {} decoding subscribers hold the producer's volume; ", n,
                           run.samples.identical, run.samples.sampled);
  if (run.errors() != 0)
    failure += fmt::format("{} subscribers: {} sequence, {} CRC, {} decode, {} stream errors (last: {}); ", n,
                           f.sequenceErrors, f.crcErrors, f.decodeErrors, f.streamErrors, f.lastError);
  if (run.connected < static_cast<uint32_t>(n)) failure += fmt::format("{} subscribers: only {} connected; ", n, run.connected);
  return failure;
}

nlohmann::json streamJson(const StreamBenchOptions& o, const std::vector<SubscriberRun>& runs) {
  nlohmann::json rows = nlohmann::json::array();
  for (const SubscriberRun& run : runs) rows.push_back(runJson(o, run));
  return {{"command", o.command},
          {"codec_format_version", kFormatVersion},
          {"volume", fmt::format("{}x{}x{} probes, bricks of 4, {}, dead-zone 1, light circling", o.grid[0], o.grid[1],
                                 o.grid[2], o.repr)},
          {"hz", o.hz},
          {"seconds", o.seconds},
          {"budget_bytes_per_s", o.budgetBytesPerSecond},
          {"ack_interval_ms", o.ackIntervalMs},
          {"link_pacing", o.linkPacing},
          {"topology", o.edges > 0 ? fmt::format("nats: the producer publishes to a nats-server (JetStream); {} edge "
                                                 "processes serve the subscribers, split evenly; server figures sum "
                                                 "producer, edges and nats-server", o.edges)
                                   : std::string("direct: one server process")},
          {"runs", rows},
          {"notes",
           "loopback; the server (producer, hub, gRPC) and the load clients run in separate processes, CPU from "
           "getrusage in each, as a fraction of one core. produce → receive: a frame's server time (the hub's publish "
           "of its newest lighting) to its arrival at a load client, same system clock. publish → write: the same "
           "start to gRPC's write-done on the server. server_cpu_core_per_subscriber and rss_kb_per_subscriber are "
           "the increase over the server's baseline (publishing to nobody) divided by subscribers. Load clients check "
           "sequence and CRCs of every frame and ack the newest at most every " +
               std::to_string(o.ackIntervalMs) + " ms; 1 in " +
               std::to_string(o.sampleEvery) + " subscribers decodes in full and is compared bit for bit with the "
               "producer's reconstruction once the lighting stops."}};
}

// Latency against subscribers: produce → receive p50 and p99, server publish → write-done p99.
std::string streamChart(const StreamBenchOptions& o, const std::vector<SubscriberRun>& runs) {
  imaging::ChartSeries p50Series{"produce → receive p50", {}, true};
  imaging::ChartSeries p99Series{"produce → receive p99", {}, true};
  imaging::ChartSeries writeSeries{"server publish → write-done p99", {}, true};
  for (const SubscriberRun& run : runs) {
    const auto n = static_cast<double>(run.subscribers);
    p50Series.points.push_back({n, std::max(1e-3, run.load1.figures.latency.percentileMs(0.5)), ""});
    p99Series.points.push_back({n, std::max(1e-3, run.load1.figures.latency.percentileMs(0.99)), ""});
    writeSeries.points.push_back({n, std::max(1e-3, run.writes.percentileMs(0.99)), ""});
  }
  imaging::ChartSpec spec;
  spec.title = "probe stream: latency against subscribers";
  spec.xLabel = "subscribers";
  spec.yLabel = "latency, ms";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = o.command;
  return imaging::renderSvgChart(spec, {p50Series, p99Series, writeSeries});
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
