// bench stream's processes: the server (a producer of lighting frames served over gRPC), the
// edges and the load clients, each a child driven by the parent's commands, and their samples.
#include "stream_parts.h"

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

namespace streaming {
namespace {

using namespace std::chrono_literals;

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

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

}  // namespace

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

}  // namespace streaming
}  // namespace probecast::bench
