// `probecast serve`: stream probes over gRPC, traced live by the updater or read from a baked
// probe file, and optionally published to NATS for edges (`subscribe` is commands_subscribe.cpp).
#include <atomic>
#include <csignal>
#include <cstdio>

#include <fmt/format.h>

#include "commands.h"
#include "probecast/codec/probe_file.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/scene_state.h"
#include "scene_options.h"

namespace probecast::app {
namespace {

std::atomic<bool> gInterrupted{false};

struct ServeOptions {
  TracingOptions tracing;
  AreaLightCli areaLights{"auto"};  // auto: live, the default; a file, its own rule
  ServerOptions server;
  std::string probes, repr = "zh3";
  std::string publish, stream = "probes";
  BusOptions bus;
  int brick = 4, deadzone = 1;
  NoiseRuleCli noise;  // on for live tracing unless --noise-scale 0
  float errorBound = 0.0f;
  uint32_t confirmations = 0;
  double hz = 10.0, seconds = 0.0, animate = 0.05, holdAfter = 0.0;
  CLI::Option* animateOption = nullptr;
};

// The scene package a probe file's viewers are sent: the one it names, with its files from
// --scene (and its lighting), checked, or from the scene cache; none when the file names none.
std::shared_ptr<const service::ScenePackage> filePackage(const SceneOptions& given, const ProbeVolume& file) {
  std::string error;
  if (!file.scene.known()) {
    if (!given.sceneGiven()) {
      fmt::print(stderr, "serve: {} names no scene (made before scenes were named): viewers must bring their own\n",
                 "the probe file");
      return nullptr;
    }
    fmt::print("serve: the probe file names no scene: describing it as {}, as given\n", given.scene);
    return std::make_shared<const service::ScenePackage>(given.package());
  }
  service::ScenePackage named;
  if (!service::parseManifest(file.scene.manifest, named, error))
    throw std::runtime_error("the probe file's scene: " + error);
  if (named.files.empty() && !given.sceneGiven()) return std::make_shared<const service::ScenePackage>(named);
  if (given.sceneGiven()) {
    const service::ScenePackage local = given.package();
    if (local.hash != named.hash)
      throw std::runtime_error("--scene " + given.scene + " (" + local.describe() + ") is not the scene the probe file "
                               "was traced in (" + named.describe() + ")");
    return std::make_shared<const service::ScenePackage>(local);
  }
  service::ScenePackage cached;
  if (service::findCachedPackage(service::defaultSceneCache(), named.hash, cached))
    return std::make_shared<const service::ScenePackage>(cached);
  throw std::runtime_error("the probe file was traced in " + named.describe() + ": give --scene " + named.scene +
                           " (and its --environment or --sky) so that viewers can be sent it");
}

// The state a file's probes were traced in: its scene time, and the lights of its scene then.
bus::SceneState fileState(const service::ScenePackage* package, const ProbeVolume& file) {
  scene::Scene s;
  if (package && !package->localSceneSpec().empty())
    s = session::loadSceneOrThrow(package->localSceneSpec(), file.scene.time);
  return session::sceneStateOf(s, file.scene.time, 0.0, service::wallClockUs());
}

// The producer of a serve: the baked file (published once, then budget ticks) or the scene traced
// live, its scene clock run by --animate scene seconds per second. `hub`, `what` and `package`
// (the scene viewers are sent) describe it.
std::unique_ptr<session::ProbeProducer> makeProducer(const ServeOptions& o, ProbeVolume& file,
                                                     std::unique_ptr<renderer::VulkanContext>& context,
                                                     service::HubConfig& hub, std::string& what,
                                                     std::shared_ptr<const service::ScenePackage>& package) {
  const Representation repr = session::parseRepresentationOrThrow(o.repr);
  const TracingOptions& tr = o.tracing;
  EncoderOptions noiseRule;  // checked before anything is read or traced
  o.noise.apply(noiseRule, o.probes.empty());
  scene::Scene s;
  ProbeGrid g;
  if (!o.probes.empty()) {
    std::string error;
    orThrow(readProbeFile(o.probes, file, error), error);
    o.areaLights.follow(file.areaLights, o.probes);  // a file's rule is what it was traced with
    hub = service::hubConfigFor(file.grid, repr, o.brick, o.deadzone);
    hub.areaLights = file.areaLights;
    package = filePackage(tr.scene, file);
    if (package) hub.scene = session::stampOf(*package, file.scene.time);
    what = o.probes;
  } else {
    s = tr.scene.load();
    g = tr.grid.resolve(s);
    hub = service::hubConfigFor(g, repr, o.brick, o.deadzone);
    package = std::make_shared<const service::ScenePackage>(tr.scene.package());
    hub.scene = session::stampOf(*package, tr.scene.t);
    what = s.name;
  }
  hub.encoder.noiseScale = noiseRule.noiseScale;
  hub.encoder.refinementInterval = noiseRule.refinementInterval;
  hub.encoder.confirmations = o.confirmations;
  if (o.confirmations > 0 && hub.encoder.noiseScale <= 0.0f)
    throw std::runtime_error("--confirmations holds back what the noise rule would re-send, and the rule is off");
  hub.encoder.errorBound = o.errorBound;
  if (o.errorBound > 0.0f && brickRepresentations(repr).size() < 2)
    throw std::runtime_error(std::string("--error-bound chooses among cheaper representations per brick: --repr ") +
                             representationName(repr) + " has none (use zh3 or l2)");
  if (!isValidLayout(hub.layout)) throw std::runtime_error("grid too large for the stream format");
  auto producer = std::make_unique<session::ProbeProducer>(hub);
  if (o.probes.empty()) {
    context = std::make_unique<renderer::VulkanContext>(tr.device.context());
    session::Animation animation;
    animation.mode = o.animate > 0 ? session::Animation::Mode::WallClock : session::Animation::Mode::Still;
    animation.start = tr.scene.t;
    animation.ratePerSecond = o.animate;
    animation.reloadScene = session::sceneMoves(tr.scene.scene, s);  // built-ins and animated glTF files
    renderer::UpdaterOptions uo = tr.updater(tr.scene.environment.load());
    uo.areaLights = o.areaLights.options();
    producer->traceScene(*context, tr.scene.scene, s, g, uo, animation);
  }
  if (!o.probes.empty()) producer->hub().setSceneState(fileState(package.get(), file));
  return producer;
}

// --repr, --brick, --deadzone, the noise rule, --confirmations and --error-bound: what the stream
// sends of each update.
void addServeStreamOptions(CLI::App* serve, ServeOptions& o) {
  addRepresentationOption(serve, o.repr, "l1, zh3h, zh3, l2 or fp16");
  serve->add_option("--brick", o.brick, "probes per brick edge")->check(CLI::Range(1, 8));
  serve->add_option("--deadzone", o.deadzone, "changes up to this many quantisation steps are not sent")
      ->check(CLI::Range(0, 127));
  o.noise.add(serve);
  serve->add_option("--confirmations", o.confirmations,
                    "with --noise-scale: a probe past the noise threshold is re-sent once it has stayed past it this "
                    "many updates more (past 4x the threshold at once; 0 = at once; bench adaptive measures 1)")
      ->check(CLI::Range(0u, 1000u));
  serve->add_option("--error-bound", o.errorBound,
                    "send each brick in the cheapest of l1, zh3, l2 (up to --repr) that keeps its probes within "
                    "this relative irradiance error (0 = every brick as --repr)")
      ->check(CLI::Range(0.0f, 10.0f));
}

// The gRPC server's options, then --publish and the bus options that need it.
void addServeNetworkOptions(CLI::App* serve, ServeOptions& o) {
  o.server.add(serve);
  CLI::Option* publish =
      serve->add_option("--publish", o.publish, "also publish every brick version to NATS JetStream (nats://host:port) for edges");
  serve->add_option("--stream", o.stream, "the volume's name on the bus (letters, digits, - and _)")->needs(publish);
  o.bus.add(serve, publish);
}

// --hz, --seconds, --hold-after and --animate: when updates are made, and for how long.
void addServePacingOptions(CLI::App* serve, ServeOptions& o) {
  serve->add_option("--hz", o.hz, "lighting updates (or budget ticks) per second")->check(CLI::Range(0.1, 1000.0));
  serve->add_option("--seconds", o.seconds, "stop after this long (0 = until interrupted)")->check(CLI::Range(0.0, 1e9));
  serve->add_option("--hold-after", o.holdAfter,
                    "publish no new lighting after this many seconds (0 = never): subscribers are still served and "
                    "settle on the last volume, to be compared bit for bit")
      ->check(CLI::Range(0.0, 1e9));
  o.animateOption =
      serve->add_option("--animate", o.animate,
                        "live: scene seconds per second (the scene clock's rate; 0: still); 0.05 by default, 0 when "
                        "--time names a moment")
          ->check(CLI::Range(0.0, 10.0));
}

// The line a serve starts with: what it serves, where, and how.
void printServing(const ServeOptions& o, session::ProbeProducer& producer, const service::ServerConfig& sc,
                  const service::HubConfig& hc, const std::string& what, int port) {
  const AreaLightRule rule = producer.hub().volume().areaLights;
  fmt::print("serve: {} on port {} ({}), {} {}x{}x{} probes, bricks of {}, {}, client area lights {}\n", what, port,
             describeSecurity(sc, "serve", port), representationName(hc.layout.repr), hc.layout.grid[0],
             hc.layout.grid[1], hc.layout.grid[2], hc.layout.brickDim, o.probes.empty() ? "live" : "from file",
             rule.on() ? fmt::format("on ({})", rule.minPowerFraction) : "off");
  if (sc.scene) fmt::print("serve: scene {}\n", sc.scene->describe());
  std::fflush(stdout);
}

void runServe(ServeOptions& o) {
  // --time alone traces that moment: the clock runs only when --animate says so.
  if (o.tracing.scene.tOption->count() > 0 && o.animateOption->count() == 0) o.animate = 0.0;
  service::ServerConfig sc = o.server.config();
  service::BusConfig bus;
  bus.url = o.publish;
  bus.stream = o.stream;
  if (!o.publish.empty()) o.bus.apply(bus);
  ProbeVolume file;
  std::unique_ptr<renderer::VulkanContext> context;
  service::HubConfig hc;
  std::string what;
  const std::unique_ptr<session::ProbeProducer> producer = makeProducer(o, file, context, hc, what, sc.scene);
  const int port = producer->serve(sc);
  if (!o.publish.empty()) {
    producer->publishTo(bus);
    fmt::print("serve: publishing to {} as stream {} (subjects {})\n", bus.url, service::busStreamName(bus.stream),
               service::busSubjects(bus.stream));
  }
  printServing(o, *producer, sc, hc, what, port);
  std::signal(SIGINT, [](int) { gInterrupted = true; });
  std::signal(SIGTERM, [](int) { gInterrupted = true; });
  if (!o.probes.empty()) producer->serveVolume(file);
  session::Pacing pacing;
  pacing.mode = session::Pacing::Mode::FixedRate;
  pacing.hz = o.hz;
  pacing.seconds = o.seconds;
  double lastReport = 0.0;
  bool held = false;
  producer->run(pacing, &gInterrupted, [&](double seconds) {
    if (o.holdAfter > 0 && seconds >= o.holdAfter && !held) {
      producer->hold(true);
      held = true;
      fmt::print("serve: holding the lighting after {} updates ({:.1f} s); volume checksum {:08x}\n",
                 producer->stats().updates, seconds, volumeChecksum(producer->hub().reconstruction()));
      std::fflush(stdout);
    }
    if (!o.publish.empty() && producer->busStats().displaced)
      throw std::runtime_error("--publish: " + producer->busStats().lastError);
    if (seconds - lastReport < 5.0) return;
    const service::PublisherStats sent = producer->busStats();
    fmt::print("serve: {:.0f} s, {} updates, {} subscribers{}\n", seconds, producer->stats().updates,
               producer->hub().subscriberCount(),
               o.publish.empty() ? std::string()
                                 : fmt::format(", bus {} ({} messages, {} bytes{})",
                                               sent.connected ? "connected" : "away", sent.messages, sent.bytes,
                                               sent.lastError.empty() ? "" : ", last error: " + sent.lastError));
    std::fflush(stdout);
    lastReport = seconds;
  });
  producer->shutdownServer();
  fmt::print("serve: stopped after {} updates\n", producer->stats().updates);
}

}  // namespace

void addServeCommand(CLI::App& app) {
  CLI::App* serve = app.add_subcommand("serve", "stream probes over gRPC (live from the updater or a probe file)");
  auto o = std::make_shared<ServeOptions>();
  o->tracing.add(serve);
  o->areaLights.add(serve, /*follows=*/true);
  serve->add_option("--probes", o->probes, "serve a baked probe volume file instead of tracing live");
  addServeStreamOptions(serve, *o);
  addServeNetworkOptions(serve, *o);
  addServePacingOptions(serve, *o);
  serve->callback([o] { runServe(*o); });
}

}  // namespace probecast::app
