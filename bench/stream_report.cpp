// bench stream's report: per subscriber count its JSON and table row, what went wrong, and the
// latency chart.
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

namespace probecast::bench::streaming {

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

}  // namespace probecast::bench::streaming
