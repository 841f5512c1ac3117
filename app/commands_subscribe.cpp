// `probecast subscribe`: a headless client of a probe stream; it reports what it received and can
// save the volume, once at the end or at ticks of the system clock.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "probecast/codec/probe_file.h"
#include "probecast/service/client.h"
#include "scene_options.h"

namespace probecast::app {
namespace {

struct SubscribeOptions {
  ConnectOptions connection;
  std::string out, repr, json, snapshotDir;
  uint64_t budget = 0;
  double seconds = 5.0, snapshotEvery = 0.0;
};

void writeSubscribeJson(const std::string& path, const service::ProbeClient& client, const service::ClientStats& st,
                        const service::VolumeSnapshot& snap) {
  nlohmann::json j;
  j["frames_applied"] = st.framesApplied;
  j["frames_rejected"] = st.framesRejected;
  j["bytes"] = st.bytesReceived;
  j["keyframes"] = st.keyframesReceived;
  j["deltas"] = st.deltasReceived;
  j["connects"] = st.connects;
  j["connect_attempts"] = st.connectAttempts;
  j["descriptions_resumed"] = st.descriptionsResumed;
  j["silences"] = st.silences;
  j["bricks"] = brickCount(snap.layout);
  j["checksum"] = fmt::format("{:08x}", volumeChecksum(snap.volume));
  j["server"] = {{"bytes_sent", st.serverBytesSent},           {"frames_acked", st.serverFramesAcked},
                 {"ack_rtt_us", st.serverAckRttUs},            {"bricks_behind", st.serverBricksBehind},
                 {"link_rate", st.serverLinkRate},             {"link_min_rtt_us", st.serverLinkMinRttUs},
                 {"link_window", st.serverLinkWindow},         {"link_in_flight", st.serverLinkInFlight},
                 {"link_waits", st.serverLinkWaits}};
  nlohmann::json frames = nlohmann::json::array();
  for (const service::AppliedFrame& f : client.appliedFrames())
    frames.push_back({f.appliedUs, f.latencyUs, f.bytes, f.keyframes, f.deltas, f.bricksHeld});
  j["frame_fields"] = {"applied_us", "latency_us", "bytes", "keyframes", "deltas", "bricks_held"};
  j["frames"] = std::move(frames);
  std::ofstream out(path);
  out << j.dump() << "\n";
  if (!out) throw std::runtime_error("cannot write " + path);
  fmt::print("wrote {}\n", path);
}

// --snapshot-every and --snapshot-dir name each other: one is no use without the other.
void addSnapshotOptions(CLI::App* sub, SubscribeOptions& so) {
  CLI::Option* every =
      sub->add_option("--snapshot-every", so.snapshotEvery,
                      "write the volume held every this many seconds, at multiples of it on the system clock (so "
                      "subscribers on one machine write theirs at the same instants): DIR/TICK.pcpv, TICK = the "
                      "Unix time divided by the period; ticks before the first volume are skipped")
          ->check(CLI::Range(0.05, 3600.0));
  sub->add_option("--snapshot-dir", so.snapshotDir, "folder for --snapshot-every (created if missing)")
      ->needs(every);
  every->needs(sub->get_option("--snapshot-dir"));
}

// Stays subscribed for --seconds (less if the server refuses), writing the volume held at every
// snapshot tick once a frame has been applied.
void staySubscribed(service::ProbeClient& client, const SubscribeOptions& so) {
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(so.seconds));
  // Snapshot ticks: multiples of the period on the system clock.
  const auto tickOf = [&](std::chrono::system_clock::time_point t) {
    return static_cast<int64_t>(std::floor(std::chrono::duration<double>(t.time_since_epoch()).count() / so.snapshotEvery));
  };
  int64_t nextTick = so.snapshotEvery > 0 ? tickOf(std::chrono::system_clock::now()) + 1 : 0;
  uint32_t written = 0;
  while (std::chrono::steady_clock::now() < end) {
    auto wake = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
    if (so.snapshotEvery > 0) {
      const auto tickAt = std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::duration<double>(static_cast<double>(nextTick) * so.snapshotEvery)));
      wake = std::min(wake, std::chrono::steady_clock::now() + (tickAt - std::chrono::system_clock::now()));
    }
    std::this_thread::sleep_until(std::min(wake, end));
    if (client.stats().fatal) break;
    if (so.snapshotEvery > 0 && tickOf(std::chrono::system_clock::now()) >= nextTick) {
      service::VolumeSnapshot held;
      if (client.snapshot(held) && held.framesApplied > 0) {  // zeros are not the server's volume
        std::string error;
        orThrow(writeProbeFile(fmt::format("{}/{}.pcpv", so.snapshotDir, nextTick), held.volume, error), error);
        ++written;
      }
      nextTick = tickOf(std::chrono::system_clock::now()) + 1;
    }
  }
  if (so.snapshotEvery > 0) fmt::print("subscribe: {} snapshots in {}\n", written, so.snapshotDir);
}

// What the server said of the stream it sent, when it said anything.
void printServerStats(const service::ClientStats& st) {
  if (st.statsReceived == 0) return;
  fmt::print("subscribe: the server counted {} bytes sent, {} frames acked, frame → ack {:.1f} ms, {} bricks behind\n",
             st.serverBytesSent, st.serverFramesAcked, st.serverAckRttUs / 1e3, st.serverBricksBehind);
  if (st.serverLinkWindow > 0)
    fmt::print("subscribe: the server paces to the link: {:.1f} kB/s, round trip {:.1f} ms, window {} bytes, "
               "{} in flight, {} waits\n",
               static_cast<double>(st.serverLinkRate) / 1e3, st.serverLinkMinRttUs / 1e3, st.serverLinkWindow, st.serverLinkInFlight,
               st.serverLinkWaits);
  else
    fmt::print("subscribe: the server does not pace this stream to its link\n");
}

void runSubscribe(const SubscribeOptions& so) {
  if (!so.snapshotDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(so.snapshotDir, ec);
    if (ec || !std::filesystem::is_directory(so.snapshotDir))
      throw std::runtime_error("cannot create the snapshot folder " + so.snapshotDir +
                               (ec ? ": " + ec.message() : std::string()));
  }
  service::ClientConfig cc = so.connection.client("probecast-subscribe");
  cc.budgetBytesPerSecond = so.budget;
  if (!so.repr.empty()) cc.representation = session::parseRepresentationOrThrow(so.repr);
  service::ProbeClient client(cc);
  client.start();
  staySubscribed(client, so);
  client.stop();
  const service::ClientStats st = client.stats();
  fmt::print("subscribe: {} frames applied, {} rejected, {} bytes, {} connects of {} attempts ({} resumed without "
             "offsets and manifest){}\n",
             st.framesApplied, st.framesRejected, st.bytesReceived, st.connects, st.connectAttempts, st.descriptionsResumed,
             st.lastError.empty() ? "" : ", last error: " + st.lastError);
  for (const std::string& line : service::refusalLines(st)) fmt::print("subscribe: refused: {}\n", line);
  if (st.fatal) throw std::runtime_error("the server refused the subscription: " + st.lastError);
  printServerStats(st);
  service::VolumeSnapshot snap;
  if (!client.snapshot(snap)) throw std::runtime_error("no volume received from " + so.connection.connect);
  service::ScenePackage named;
  std::string why;
  fmt::print("subscribe: {} at scene time {:.4f} (clock offset {:.1f} ms)\n",
             snap.volume.scene.known() && service::parseManifest(snap.volume.scene.manifest, named, why)
                 ? "scene " + named.describe()
                 : std::string("no scene named"),
             snap.volume.scene.time, static_cast<double>(snap.clockOffsetUs) / 1e3);
  fmt::print("subscribe: volume checksum {:08x} ({} probes)\n", volumeChecksum(snap.volume), snap.volume.grid.count());
  if (!so.json.empty()) writeSubscribeJson(so.json, client, st, snap);
  if (!so.out.empty()) {
    // A volume no frame was applied to is zeros, not the server's: nothing is written.
    if (st.framesApplied == 0)
      throw std::runtime_error("no frame applied from " + so.connection.connect + ": nothing written to " + so.out);
    std::string error;
    orThrow(writeProbeFile(so.out, snap.volume, error), error);
    fmt::print("wrote {}\n", so.out);
  }
}

}  // namespace

void addSubscribeCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("subscribe", "subscribe to a probe stream; report and save the volume");
  auto so = std::make_shared<SubscribeOptions>();
  so->connection.add(sub, "server address host:port (several comma-separated: edges to fail over between)", true, true);
  so->connection.addLimits(sub);
  sub->add_option("--budget", so->budget, "bytes per second this subscriber accepts (0 = unlimited)");
  sub->add_option("--seconds", so->seconds, "how long to stay subscribed")->check(CLI::Range(0.1, 1e9));
  sub->add_option("--out", so->out, "write the received volume here (probe volume file)");
  sub->add_option("--json", so->json,
                  "write what was received here as JSON: totals, the server's link estimate, and every frame applied "
                  "(when, its latency from the publish of its lighting, bytes, keyframes, bricks held)");
  addRepresentationOption(sub, so->repr, "representation wanted (default: the server's; a coarser one is transcoded)");
  addSnapshotOptions(sub, *so);
  sub->callback([so] { runSubscribe(*so); });
}

}  // namespace probecast::app
