// `probecast serve` (live from the updater, or a baked probe file) and `probecast subscribe`.
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

#include <fmt/format.h>

#include "commands.h"
#include "probecast/codec/probe_file.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/volumes.h"
#include "scene_options.h"

namespace probecast::app {
namespace {

std::atomic<bool> gInterrupted{false};

std::string tokenFrom(const std::string& token, const std::string& file) {
  if (!file.empty()) {
    std::string t = readTextFile(file);
    while (!t.empty() && (t.back() == '\n' || t.back() == '\r' || t.back() == ' ')) t.pop_back();
    return t;
  }
  return token;
}

// A producer for the hub, once its layout is known to fit the stream format.
std::unique_ptr<session::ProbeProducer> makeProducer(const service::HubConfig& hc) {
  if (!isValidLayout(hc.layout)) throw std::runtime_error("grid too large for the stream format");
  return std::make_unique<session::ProbeProducer>(hc);
}

}  // namespace

void addServeCommands(CLI::App& app, int& exitCode) {
  CLI::App* serve = app.add_subcommand("serve", "stream probes over gRPC (live from the updater or a probe file)");
  auto tr = std::make_shared<TracingOptions>();
  struct Options {
    std::string probes, repr = "zh3", listen = "127.0.0.1:50051", tlsCert, tlsKey, token, tokenFile;
    bool plaintext = false;
    int brick = 4, deadzone = 1;
    double hz = 10.0, seconds = 0.0, animate = 0.05;
  };
  auto o = std::make_shared<Options>();
  tr->add(serve);
  serve->add_option("--probes", o->probes, "serve a baked probe volume file instead of tracing live");
  addRepresentationOption(serve, o->repr, "l1, zh3h, zh3, l2 or fp16");
  serve->add_option("--brick", o->brick, "probes per brick edge")->check(CLI::Range(1, 8));
  serve->add_option("--deadzone", o->deadzone, "changes up to this many quantisation steps are not sent")
      ->check(CLI::Range(0, 127));
  serve->add_option("--listen", o->listen, "address to listen on (host:port)");
  serve->add_option("--tls-cert", o->tlsCert, "PEM certificate file")->check(CLI::ExistingFile);
  serve->add_option("--tls-key", o->tlsKey, "PEM private key file")->check(CLI::ExistingFile);
  serve->add_flag("--plaintext", o->plaintext, "serve without TLS (trusted networks only)");
  serve->add_option("--token", o->token, "bearer token every call must present");
  serve->add_option("--token-file", o->tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
  serve->add_option("--hz", o->hz, "lighting updates (or budget ticks) per second")->check(CLI::Range(0.1, 1000.0));
  serve->add_option("--seconds", o->seconds, "stop after this long (0 = until interrupted)")->check(CLI::Range(0.0, 1e9));
  serve->add_option("--animate", o->animate, "live: animation parameter t advanced per second")->check(CLI::Range(0.0, 10.0));
  serve->callback([=, &exitCode] {
    service::ServerConfig sc;
    sc.listen = o->listen;
    sc.token = tokenFrom(o->token, o->tokenFile);
    sc.plaintext = o->plaintext;
    if (!o->tlsCert.empty() || !o->tlsKey.empty()) {
      if (o->tlsCert.empty() || o->tlsKey.empty()) throw std::runtime_error("--tls-cert and --tls-key go together");
      sc.tlsCertPem = readTextFile(o->tlsCert);
      sc.tlsKeyPem = readTextFile(o->tlsKey);
    }
    if (sc.tlsCertPem.empty() && !sc.plaintext)
      throw std::runtime_error("give --tls-cert and --tls-key, or --plaintext to serve without TLS");
    if (sc.token.empty()) fmt::print(stderr, "serve: warning: no --token, anyone who reaches the port may subscribe\n");

    const Representation repr = session::parseRepresentationOrThrow(o->repr);
    ProbeVolume volume;
    service::HubConfig hc;
    std::unique_ptr<renderer::VulkanContext> context;
    std::unique_ptr<session::ProbeProducer> producer;
    scene::Scene s;
    if (!o->probes.empty()) {
      std::string error;
      if (!readProbeFile(o->probes, volume, error)) throw std::runtime_error(error);
      hc = session::hubConfigFor(volume, repr, o->brick, o->deadzone);
      producer = makeProducer(hc);
    } else {
      s = tr->scene.load();
      const renderer::ProbeGrid g = tr->grid.resolve(s);
      hc = session::hubConfigFor(g, repr, o->brick, o->deadzone);
      producer = makeProducer(hc);
      context = std::make_unique<renderer::VulkanContext>(tr->gpu.context());
      session::Animation animation;  // --animate: t advances per update, so per second at --hz
      animation.mode = o->animate > 0 ? session::Animation::Mode::PerStep : session::Animation::Mode::Still;
      animation.start = tr->scene.t;
      animation.perStep = static_cast<float>(o->animate / o->hz);
      producer->traceScene(*context, tr->scene.scene, s, g, tr->tracer.options(), animation);
    }
    const int port = producer->serve(sc);
    fmt::print("serve: {} on port {} ({}), {} {}x{}x{} probes, bricks of {}, {}\n",
               o->probes.empty() ? s.name : o->probes, port, sc.tlsCertPem.empty() ? "plaintext" : "TLS",
               representationName(hc.layout.repr), hc.layout.grid[0], hc.layout.grid[1], hc.layout.grid[2],
               hc.layout.brickDim, o->probes.empty() ? "live" : "from file");
    std::fflush(stdout);
    std::signal(SIGINT, [](int) { gInterrupted = true; });
    std::signal(SIGTERM, [](int) { gInterrupted = true; });
    if (!o->probes.empty()) producer->serveVolume(volume.probes, volume.active);
    session::Pacing pacing;
    pacing.mode = session::Pacing::Mode::FixedRate;
    pacing.hz = o->hz;
    pacing.seconds = o->seconds;
    double lastReport = 0.0;
    producer->run(pacing, &gInterrupted, [&](double seconds) {
      if (seconds - lastReport < 5.0) return;
      fmt::print("serve: {:.0f} s, {} updates, {} subscribers\n", seconds, producer->stats().updates,
                 producer->hub().subscriberCount());
      std::fflush(stdout);
      lastReport = seconds;
    });
    const uint32_t frames = producer->stats().updates;
    producer->shutdownServer();
    fmt::print("serve: stopped after {} updates\n", frames);
    exitCode = 0;
  });

  CLI::App* sub = app.add_subcommand("subscribe", "subscribe to a probe stream; report and save the volume");
  struct SubOptions {
    std::string connect, token, tokenFile, tlsCa, tlsName, out;
    uint64_t budget = 0;
    double seconds = 5.0;
  };
  auto so = std::make_shared<SubOptions>();
  sub->add_option("--connect", so->connect, "server address host:port")->required();
  sub->add_option("--token", so->token, "bearer token");
  sub->add_option("--token-file", so->tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
  sub->add_option("--tls-ca", so->tlsCa, "PEM root certificate to trust (enables TLS)")->check(CLI::ExistingFile);
  sub->add_option("--tls-name", so->tlsName, "server name to check in its certificate");
  sub->add_option("--budget", so->budget, "bytes per second this subscriber accepts (0 = unlimited)");
  sub->add_option("--seconds", so->seconds, "how long to stay subscribed")->check(CLI::Range(0.1, 1e9));
  sub->add_option("--out", so->out, "write the received volume here (probe volume file)");
  sub->callback([=, &exitCode] {
    service::ClientConfig cc;
    cc.address = so->connect;
    cc.token = tokenFrom(so->token, so->tokenFile);
    cc.budgetBytesPerSecond = so->budget;
    cc.name = "probecast-subscribe";
    if (!so->tlsCa.empty()) {
      cc.tls = true;
      cc.rootCertPem = readTextFile(so->tlsCa);
      cc.tlsServerName = so->tlsName;
    }
    service::ProbeClient client(cc);
    client.start();
    const auto start = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - start < std::chrono::duration<double>(so->seconds)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      if (client.stats().fatal) break;
    }
    client.stop();
    const service::ClientStats st = client.stats();
    fmt::print("subscribe: {} frames applied, {} rejected, {} bytes, {} connects{}\n", st.framesApplied,
               st.framesRejected, st.bytesReceived, st.connects, st.lastError.empty() ? "" : ", last error: " + st.lastError);
    if (st.fatal) throw std::runtime_error("the server refused the subscription: " + st.lastError);
    service::VolumeSnapshot snap;
    if (!client.snapshot(snap)) throw std::runtime_error("no volume received from " + so->connect);
    if (!so->out.empty()) {
      const ProbeVolume v = session::fileFromSnapshot(snap);
      std::string error;
      if (!writeProbeFile(so->out, v, error)) throw std::runtime_error(error);
      fmt::print("wrote {}\n", so->out);
    }
    exitCode = 0;
  });
}

}  // namespace probecast::app
