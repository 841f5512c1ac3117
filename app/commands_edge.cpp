// `probecast edge`: a stateless edge server fed from the probe bus.
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

#include <fmt/format.h>

#include "commands.h"
#include "probecast/service/edge_server.h"
#include "options/connect.h"
#include "scene_options.h"

namespace probecast::app {
namespace {

std::atomic<bool> gEdgeInterrupted{false};

}  // namespace

void addEdgeCommand(CLI::App& app) {
  CLI::App* edge = app.add_subcommand("edge", "serve a producer's probe stream from NATS JetStream (a stateless edge)");
  struct EdgeOptions {
    ServerOptions server;
    service::BusConfig bus;
    BusOptions busLink;
    uint32_t maxSubscribers = 1024;
    double seconds = 0.0;
    ConnectOptions sceneFrom;
    std::string sceneCache;
  };
  auto o = std::make_shared<EdgeOptions>();
  edge->add_option("--nats", o->bus.url, "NATS server(s) holding the stream: nats://host:port, comma-separated")
      ->required();
  edge->add_option("--stream", o->bus.stream, "the volume's name on the bus, as given to serve --stream");
  o->busLink.add(edge);
  o->server.add(edge);
  edge->add_option("--max-subscribers", o->maxSubscribers, "subscribers served at once")->check(CLI::Range(1, 1000000));
  edge->add_option("--seconds", o->seconds, "stop after this long (0 = until interrupted)")->check(CLI::Range(0.0, 1e9));
  edge->add_option("--scene-from", o->sceneFrom.connect,
                   "fetch the scene the bus names from this server (the producer or another edge, host:port), to "
                   "deliver it to viewers; built-in scenes need nothing");
  edge->add_option("--scene-from-token-file", o->sceneFrom.tokenFile, "bearer token for --scene-from")
      ->check(CLI::ExistingFile);
  edge->add_option("--scene-from-ca", o->sceneFrom.tlsCa, "PEM root certificate of --scene-from (enables TLS)")
      ->check(CLI::ExistingFile);
  edge->add_option("--scene-cache", o->sceneCache,
                   "folder of scenes by hash (default $PROBECAST_SCENE_CACHE, else ~/.cache/probecast/scenes)");
  edge->callback([o] {
    service::EdgeConfig ec;
    ec.bus = o->bus;
    o->busLink.apply(ec.bus);
    ec.server = o->server.config();
    ec.server.maxSubscribers = o->maxSubscribers;
    if (!o->sceneFrom.connect.empty()) ec.sceneSource = o->sceneFrom.client("probecast-edge");
    if (!o->sceneCache.empty()) ec.sceneCache = o->sceneCache;
    service::EdgeServer server(ec);
    fmt::print("edge: stream {} from {} on port {} ({})\n", service::busStreamName(ec.bus.stream), ec.bus.url,
               server.port(), describeSecurity(ec.server, "edge", server.port()));
    std::fflush(stdout);
    std::signal(SIGINT, [](int) { gEdgeInterrupted = true; });
    std::signal(SIGTERM, [](int) { gEdgeInterrupted = true; });
    const auto start = std::chrono::steady_clock::now();
    auto lastReport = start;
    while (!gEdgeInterrupted) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const auto now = std::chrono::steady_clock::now();
      if (o->seconds > 0 && now - start >= std::chrono::duration<double>(o->seconds)) break;
      if (now - lastReport < std::chrono::seconds(5)) continue;
      lastReport = now;
      const service::EdgeStats st = server.stats();
      fmt::print("edge: bus {}, {} messages ({} applied, {} stale, {} refused), {} subscribers, scene {}{}\n",
                 st.busConnected ? "connected" : "away", st.received, st.applied, st.stale, st.refused,
                 server.hub().subscriberCount(), st.scene.empty() ? "not yet held" : st.scene,
                 st.lastError.empty() ? "" : ", last error: " + st.lastError);
      std::fflush(stdout);
    }
    server.shutdown();
    const service::EdgeStats st = server.stats();
    fmt::print("edge: stopped; {} messages ({} applied, {} refused), {} epochs\n", st.received, st.applied, st.refused,
               st.epochs);
  });
}

}  // namespace probecast::app
