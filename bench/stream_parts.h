// The parts of `probecast bench stream` (stream_bench.h) that its files share: the child
// processes a run is made of (server, edges, load clients) and what they report, one run per
// subscriber count, and its report.
#pragma once

#include <sys/types.h>

#include <array>
#include <chrono>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "load_client.h"
#include "probecast/service/bus_nats.h"
#include "probecast/service/server.h"
#include "probecast/testing/child_process.h"
#include "stream_bench.h"

namespace probecast::bench::streaming {

constexpr const char* kBenchToken = "bench";  // the server requires one; loopback only

// What the server side of a run is made of; the direct topology is one server process, and a
// relayed one (an origin, a message bus, edges) adds processes whose CPU and memory count too.
struct ProcessSample {
  double cpuSeconds = 0;
  double rssKb = 0;
};

// A child's answer to `command`: its next line, which must start with `expect`; the rest of it.
std::string ask(testing::ChildProcess& child, const std::string& command, const std::string& expect,
                const std::string& who);
ProcessSample parseSample(const std::string& text, const std::string& who);
// CPU seconds and resident kB of another process (nats-server), from /proc.
ProcessSample sampleProcess(pid_t pid);

// The server process: a producer of lighting frames at `hz`, served over gRPC, driven by the
// parent's commands (sample, latency, stop, quit) so that baseline and load are measured apart.
// With `bus`, it also publishes every brick version there (the relayed topology's origin).
int serveLightingFrames(double hz, const std::string& repr, std::array<uint16_t, 3> dims, const service::BusConfig* bus,
                        const testing::ChildProcess::Say& say, const testing::ChildProcess::Hear& hear);

struct LoadReport {
  ProcessSample process;
  LoadFigures figures;
};

// A load process: `config`'s subscribers, driven by the parent's commands (take, check, quit).
int runLoad(const LoadClientConfig& config, const testing::ChildProcess::Say& say,
            const testing::ChildProcess::Hear& hear);
LoadReport parseFigures(const std::string& text, const std::string& who);

// An edge process: an edge server fed from `bus`, driven like the server process (sample,
// latency, quit). It says its port once the bus has delivered the volume, so subscribers that
// connect then are served rather than told to go elsewhere.
int serveEdge(const service::BusConfig& bus, const testing::ChildProcess::Say& say,
              const testing::ChildProcess::Hear& hear);

// A top-down orthographic view of an 8 m patch from 20 m up, centred somewhere over the grid
// (`dims`, 1 m apart): clip x = (x − cx)/4, clip y = (z − cz)/4, clip z = (20 − y)/30
// (column-major, m[col * 4 + row]).
View randomView(uint32_t index, std::array<uint16_t, 3> dims);
double secondsSince(std::chrono::steady_clock::time_point t);

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

// The report (stream_report.cpp): a run's JSON and table row, what went wrong in it (empty:
// nothing), the whole JSON and the latency chart.
nlohmann::json runJson(const StreamBenchOptions& o, const SubscriberRun& run);
std::string tableRow(const SubscriberRun& run);
std::string runFailures(const SubscriberRun& run);
nlohmann::json streamJson(const StreamBenchOptions& o, const std::vector<SubscriberRun>& runs);
std::string streamChart(const StreamBenchOptions& o, const std::vector<SubscriberRun>& runs);

}  // namespace probecast::bench::streaming
