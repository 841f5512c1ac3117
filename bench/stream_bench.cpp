#include "stream_bench.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/session/child_process.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {
namespace {

using namespace std::chrono_literals;
using session::percentile;

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

}  // namespace

void lightingFrame(int frame, std::vector<float>& probes) {
  const int nx = kLightingGrid[0], ny = kLightingGrid[1], nz = kLightingGrid[2];
  probes.assign(static_cast<size_t>(nx) * ny * nz * 27, 0.0f);
  const float a = 0.05f * static_cast<float>(frame);
  const float light[3] = {16.0f + 10.0f * std::cos(a), 10.0f, 16.0f + 10.0f * std::sin(a)};
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

struct ServerReport {
  double cpuSeconds = 0;
  double encodeMsPerFrame = 0;
  int frames = 0;
};

// The server side, in a process of its own: a producer of lighting frames served for `seconds`;
// says "port N", then "report CPU_SECONDS ENCODE_MS_PER_FRAME FRAMES".
int serveLightingFrames(double hz, double seconds, const std::string& repr, const session::ChildProcess::Say& say) {
  session::ProbeProducer producer(service::hubConfigFor(
      session::unitGrid({kLightingGrid[0], kLightingGrid[1], kLightingGrid[2]}),
      parseRepresentation(repr).value_or(Representation::Zh3), 4, 1));
  service::ServerConfig sc;
  sc.plaintext = true;
  sc.token = "bench";
  sc.maxSubscribers = 100000;
  say(fmt::format("port {}", producer.serve(sc)));
  const double cpu0 = cpuSeconds();
  producer.generate([](uint32_t frame, std::vector<float>& probes) { lightingFrame(static_cast<int>(frame), probes); });
  session::Pacing pacing;
  pacing.mode = session::Pacing::Mode::FixedRate;
  pacing.hz = hz;
  pacing.seconds = seconds;
  producer.run(pacing);
  producer.shutdownServer();
  const session::ProducerStats st = producer.stats();
  say(fmt::format("report {:.6f} {:.6f} {}", cpuSeconds() - cpu0, st.publishMs / std::max<double>(st.updates, 1),
                  st.updates));
  return 0;
}

}  // namespace

namespace {

// A top-down orthographic view of an 8 m patch from 20 m up: clip x = (x − cx)/4,
// clip y = (z − cz)/4, clip z = (20 − y)/30 (column-major, m[col * 4 + row]).
View randomView(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 31.0f);
  const float cx = u(rng), cz = u(rng), h = 4.0f;
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

}  // namespace

StreamBenchResult runStreamBench(const StreamBenchOptions& o) {
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  nlohmann::json runs = nlohmann::json::array();
  imaging::ChartSeries bytesSeries{"bytes/s per subscriber (mean)", {}, true};
  imaging::ChartSeries cpuSeries{"server CPU ms/s per subscriber", {}, true};
  std::string table = fmt::format("{:>6} {:>16} {:>16} {:>12} {:>12} {:>16} {:>14}\n", "subs", "B/s/sub mean",
                                  "B/s/sub p99", "lat p50 ms", "lat p99 ms", "server CPU %/sub", "encode ms/frm");
  for (int n : o.subscribers)
    if (n < 1) throw std::invalid_argument("subscriber counts must be positive");
  const double serverSeconds = o.seconds + 2.0;  // margin for connecting
  // One server process per run, all forked now, before this process starts gRPC.
  std::vector<std::unique_ptr<session::ChildProcess>> servers;
  for (size_t k = 0; k < o.subscribers.size(); ++k)
    servers.push_back(std::make_unique<session::ChildProcess>(
        [&o, serverSeconds](const session::ChildProcess::Say& tell) {
          return serveLightingFrames(o.hz, serverSeconds, o.repr, tell);
        }));
  for (size_t k = 0; k < o.subscribers.size(); ++k) {
    const int n = o.subscribers[k];
    session::ChildProcess& server = *servers[k];
    server.go();
    int port = 0;
    std::string line;
    if (!server.readLine(line) || std::sscanf(line.c_str(), "port %d", &port) != 1)
      throw std::runtime_error("server process did not start");
    say(fmt::format("{} subscribers on port {}, {:.0f} s at {} Hz", n, port, o.seconds, o.hz));
    std::mt19937 rng(7);
    std::vector<std::unique_ptr<service::ProbeClient>> clients;
    for (int i = 0; i < n; ++i) {
      service::ClientConfig cc;
      cc.address = "127.0.0.1:" + std::to_string(port);
      cc.token = "bench";
      cc.budgetBytesPerSecond = o.budgetBytesPerSecond;
      clients.push_back(std::make_unique<service::ProbeClient>(cc));
      clients.back()->setViews({randomView(rng)});
      clients.back()->start();
    }
    std::this_thread::sleep_for(1s);  // let everyone join and take the first keyframes
    std::vector<uint64_t> bytes0(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) bytes0[i] = clients[i]->stats().bytesReceived;
    const auto t0 = std::chrono::steady_clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds - 1.0));
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<double> rates, latencies;
    for (int i = 0; i < n; ++i) {
      rates.push_back(static_cast<double>(clients[i]->stats().bytesReceived - bytes0[i]) / dt);
      for (uint32_t l : clients[i]->latenciesUs()) latencies.push_back(l / 1000.0);
    }
    uint32_t rejected = 0, connected = 0;
    if (!clients.empty() && clients[0]->stats().connects == 0)
      say("first subscriber never connected: " + clients[0]->stats().lastError);
    for (auto& c : clients) {
      rejected += c->stats().framesRejected;
      connected += c->stats().connects > 0 ? 1 : 0;
      c->stop();
    }
    clients.clear();
    ServerReport report;
    if (!server.readLine(line) ||
        std::sscanf(line.c_str(), "report %lf %lf %d", &report.cpuSeconds, &report.encodeMsPerFrame, &report.frames) !=
            3)
      throw std::runtime_error("server process did not report");
    server.wait();
    double mean = 0;
    for (double r : rates) mean += r;
    mean /= n;
    const double cpuPerSub = report.cpuSeconds / serverSeconds / n;  // fraction of a core
    const nlohmann::json run = {{"subscribers", n},
                                {"connected", connected},
                                {"bytes_per_s_per_sub", mean},
                                {"bytes_per_s_per_sub_p99", percentile(rates, 0.99)},
                                {"latency_ms_p50", percentile(latencies, 0.5)},
                                {"latency_ms_p99", percentile(latencies, 0.99)},
                                {"server_cpu_per_sub", cpuPerSub},
                                {"server_cpu_total", report.cpuSeconds / serverSeconds},
                                {"encode_ms_per_frame", report.encodeMsPerFrame},
                                {"frames_published", report.frames},
                                {"frames_rejected", rejected}};
    runs.push_back(run);
    table += fmt::format("{:>6} {:>16.0f} {:>16.0f} {:>12.2f} {:>12.2f} {:>16.3f} {:>14.2f}\n", n, mean,
                         percentile(rates, 0.99), percentile(latencies, 0.5), percentile(latencies, 0.99),
                         100 * cpuPerSub, report.encodeMsPerFrame);
    bytesSeries.points.push_back({static_cast<double>(n), mean, ""});
    cpuSeries.points.push_back({static_cast<double>(n), 1000 * cpuPerSub, ""});
  }
  StreamBenchResult r;
  r.json = {{"command", o.command},
            {"volume", "32x8x32 probes, bricks of 4, " + o.repr + ", dead-zone 1, light circling"},
            {"hz", o.hz},
            {"seconds", o.seconds},
            {"budget_bytes_per_s", o.budgetBytesPerSecond},
            {"runs", runs},
            {"notes", "loopback, server in a child process; latency = client decode time minus the server time of "
                      "the frame's lighting; CPU as a fraction of one core"}};
  r.table = table;
  imaging::ChartSpec spec;
  spec.title = "probe stream: per-subscriber cost against subscribers";
  spec.xLabel = "subscribers";
  spec.yLabel = "bytes/s per subscriber; server CPU ms/s per subscriber";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = o.command;
  r.svg = imaging::renderSvgChart(spec, {bytesSeries, cpuSeries});
  return r;
}

}  // namespace probecast::bench
