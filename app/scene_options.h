// Options shared by the commands that load a scene, trace probes or use Vulkan.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "commands.h"
#include "probecast/renderer/environment.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/service/bus_nats.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/scene/area_lights.h"
#include "probecast/scene/scene.h"
#include "probecast/session/representation.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/volumes.h"

namespace probecast::app {

// Distant light around the scene: --environment FILE (.hdr or .exr, equirect) with
// --environment-intensity K and --environment-rotation DEG, or a uniform --sky R,G,B. The map's
// convention is renderer/environment.h's (top row +Y, centre −Z, u = 0.75 toward +X; positive
// rotation turns it counter-clockwise seen from above, the centre toward −X).
struct EnvironmentOptions {
  std::string file;
  float intensity = 1.0f, rotationDeg = 0.0f;
  std::vector<float> sky;
  void add(CLI::App* cmd) {
    CLI::Option* e = cmd->add_option(
        "--environment", file, "equirect environment map (.hdr or .exr): top row +Y, image centre facing -Z");
    cmd->add_option("--environment-intensity", intensity, "scale of the environment map's radiance (>= 0)")->needs(e);
    cmd->add_option("--environment-rotation", rotationDeg,
                    "turn the map about +Y, degrees (counter-clockwise seen from above)")
        ->needs(e);
    cmd->add_option("--sky", sky, "uniform sky radiance R,G,B instead of a map")->delimiter(',')->expected(3)->excludes(e);
  }
  bool given() const { return !file.empty() || !sky.empty(); }
  // The environment, or null when neither option is given; throws with a clear message for a
  // missing or unreadable file, non-finite pixels, or a negative or NaN intensity or sky value.
  std::shared_ptr<const renderer::Environment> load() const {
    if (!given()) return nullptr;
    auto env = std::make_shared<renderer::Environment>();
    std::string error;
    const bool ok = !file.empty() ? renderer::loadEnvironment(file, intensity, rotationDeg, *env, error)
                                  : renderer::makeUniformSky({sky[0], sky[1], sky[2]}, *env, error);
    if (!ok) throw std::runtime_error((!file.empty() ? "--environment: " : "--sky: ") + error);
    return env;
  }
};

struct SceneOptions {
  std::string scene = "builtin:cornell";
  float t = 0.0f;
  EnvironmentOptions environment;
  void add(CLI::App* cmd) {
    cmd->add_option("--scene", scene, "glTF file or builtin:NAME (cornell, closed-box, thin-wall, hall)");
    cmd->add_option("--t", t, "animation parameter of built-in scenes")->check(CLI::Range(0.0f, 1.0f));
    environment.add(cmd);
  }
  scene::Scene load() const { return session::loadSceneOrThrow(scene, t); }
};

// --device auto|gpu|cpu and --validation: the Vulkan device probes are traced and views drawn on.
struct GpuOptions {
  renderer::DeviceChoice device = renderer::DeviceChoice::Auto;
  bool validation = false;
  void add(CLI::App* cmd) {
    cmd->add_option_function<std::string>(
           "--device",
           [this](const std::string& text) {
             if (!renderer::parseDeviceChoice(text, device))
               throw CLI::ValidationError("--device", "'" + text + "' is not auto, gpu or cpu");
           },
           "auto: a GPU with ray tracing when one is present, lavapipe otherwise; gpu or cpu: that kind or an error")
        ->default_str("auto");
    cmd->add_flag("--validation", validation, "enable the Vulkan validation layer");
  }
  renderer::ContextOptions context() const {
    renderer::ContextOptions o;
    o.device = device;
    o.validation = validation;
    return o;
  }
};

struct GridOptions {
  std::vector<uint32_t> dims{8, 8, 8};
  std::vector<float> bounds;  // empty: cell-centred in the scene bounds
  // --grid (each count in [minDim, maxDim]) and, when withBounds, --bounds.
  void add(CLI::App* cmd, bool withBounds = true, uint32_t minDim = 1, uint32_t maxDim = 1024) {
    cmd->add_option("--grid", dims, "probes along X,Y,Z")->delimiter(',')->expected(3)->check(CLI::Range(static_cast<int>(minDim), static_cast<int>(maxDim)));
    if (!withBounds) return;
    cmd->add_option("--bounds", bounds, "minX,minY,minZ,maxX,maxY,maxZ of the first and last probe (metres)")
        ->delimiter(',')
        ->expected(6);
  }
  // The grid: the first and last probe at --bounds, or cell-centred over the scene's bounds.
  ProbeGrid resolve(const scene::Scene& s) const {
    if (static_cast<uint64_t>(dims[0]) * dims[1] * dims[2] > (1u << 24)) throw std::runtime_error("grid too large");
    if (bounds.size() != 6) return renderer::sceneGrid(s, {dims[0], dims[1], dims[2]});
    for (float b : bounds)
      if (!std::isfinite(b)) throw std::runtime_error("--bounds must be finite");
    return ProbeGrid{{dims[0], dims[1], dims[2]}, {{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}}};
  }
};

// --spp (samples per probe per update, or per pixel), with each command's own default and limit.
inline CLI::Option* addSppOption(CLI::App* cmd, uint32_t& spp,
                                 const std::string& what = "samples (paths) per probe per update",
                                 uint32_t max = 1u << 16) {
  return cmd->add_option("--spp", spp, what)->check(CLI::Range(1, static_cast<int>(max)));
}

// --reference-spp: samples per pixel of the reference images.
inline CLI::Option* addReferenceSppOption(CLI::App* cmd, uint32_t& spp, uint32_t max,
                                          const std::string& what = "samples per pixel of the reference") {
  return cmd->add_option("--reference-spp", spp, what)->check(CLI::Range(1, static_cast<int>(max)));
}

// --shadow-cascades N: orthographic layers per directional light (RasterOptions::shadowCascades).
inline CLI::Option* addShadowCascadesOption(CLI::App* cmd, uint32_t& cascades) {
  return cmd->add_option("--shadow-cascades", cascades, "shadow cascades per directional light (1 = one layer over the scene)")
      ->check(CLI::Range(1, 4));
}

// --size WxH, each in [min, max].
inline CLI::Option* addSizeOption(CLI::App* cmd, std::vector<uint32_t>& size, const std::string& what, uint32_t min,
                                  uint32_t max) {
  return cmd->add_option("--size", size, what)->delimiter('x')->expected(2)->check(CLI::Range(static_cast<int>(min), static_cast<int>(max)));
}

// --visibility on|off: probe visibility in the raster client (RasterOptions::visibility).
inline CLI::Option* addVisibilityOption(CLI::App* cmd, bool& visibility) {
  return cmd
      ->add_option_function<std::string>(
          "--visibility", [&visibility](const std::string& v) { visibility = v == "on"; },
          "raster client: weigh probes by visibility from depth moments (on) or plain trilinear (off)")
      ->check(CLI::IsMember({"on", "off"}));
}

// --json FILE, required by every benchmark.
inline CLI::Option* addJsonOption(CLI::App* cmd, std::string& json) {
  return cmd->add_option("--json", json, "write the results as JSON here")->required();
}

// --repr (or another name) checked by the one representation parser; `allowFloat` admits "float"
// (probes as traced).
inline CLI::Option* addRepresentationOption(CLI::App* cmd, std::string& repr, const std::string& what,
                                            bool allowFloat = false, const std::string& name = "--repr") {
  return cmd->add_option(name, repr, what)->check(CLI::Validator(
      [allowFloat](std::string& value) { return session::checkRepresentation(value, allowFloat); },
      allowFloat ? "{float,l1,zh3h,zh3,l2,fp16}" : "{l1,zh3h,zh3,l2,fp16}"));
}

// The noise-aware stream of serve and demo (EncoderOptions::noiseScale and refinementInterval):
// a probe is re-sent only when its change exceeds what its Monte Carlo noise explains, and
// refinements of probes whose light held still wait for every Kth update. On by default wherever
// probes are traced live (docs/MEASUREMENTS.md, "Defaults", has the figures behind these values);
// --noise-scale 0 turns it off, and the refinement interval with it unless one is given.
inline constexpr float kNoiseScaleDefault = 1.6f;
inline constexpr uint32_t kRefinementIntervalDefault = 8;

struct NoiseRuleCli {
  float scale = kNoiseScaleDefault;
  uint32_t refinementInterval = kRefinementIntervalDefault;
  CLI::Option* scaleOption = nullptr;
  CLI::Option* intervalOption = nullptr;
  void add(CLI::App* cmd) {
    scaleOption = cmd->add_option("--noise-scale", scale,
                                  "live tracing: a probe is not re-sent while its change stays within this many "
                                  "standard errors of its Monte Carlo noise (0 = off)")
                      ->check(CLI::Range(0.0f, 1000.0f))
                      ->capture_default_str();
    intervalOption = cmd->add_option("--refinement-interval", refinementInterval,
                                     "with the noise rule: refinements (changes within twice the noise threshold of "
                                     "probes whose light held still this many updates) wait for the next update "
                                     "whose sequence is a multiple of this, every brick's going in that one frame "
                                     "(0 = at once)")
                         ->check(CLI::Range(0u, 100000u))
                         ->capture_default_str();
  }
  bool scaleGiven() const { return scaleOption && scaleOption->count() > 0; }
  bool intervalGiven() const { return intervalOption && intervalOption->count() > 0; }
  // The rule into `encoder`: as given (or the defaults) for live tracing; off for probes from a
  // file, which carry no per-probe noise. Throws std::runtime_error when what was given cannot
  // hold: a scale for a file, or a refinement interval with the rule off.
  void apply(EncoderOptions& encoder, bool live) const {
    if (!live && scaleGiven() && scale > 0.0f)
      throw std::runtime_error("--noise-scale needs live tracing: a --probes file carries no per-probe noise");
    const bool on = live && scale > 0.0f;
    if (!on && intervalGiven() && refinementInterval > 0)
      throw std::runtime_error("--refinement-interval holds back what the noise rule calls refinements, and the rule is " +
                               std::string(live ? "off (--noise-scale 0)" : "off for a --probes file"));
    encoder.noiseScale = on ? scale : 0.0f;
    encoder.refinementInterval = on ? refinementInterval : 0;
  }
};

struct TracerOptions {
  uint32_t spp = 128;
  uint32_t bounces = 4;
  uint32_t seed = 1;
  float wMin = renderer::UpdaterOptions{}.minBlendWeight;
  float rejectSigmas = 4.0f;
  float neighbourHistory = renderer::UpdaterOptions{}.neighbourHistory;
  float changeHistory = renderer::UpdaterOptions{}.changeHistory;
  float clamp = 16.0f;
  bool relocate = true;
  bool surfaceProbesOnly = true;
  uint64_t raysPerUpdate = 0;
  void add(CLI::App* cmd) {
    addSppOption(cmd, spp);
    cmd->add_option("--rays-per-update", raysPerUpdate,
                    "paths per update spent over the probes by need (in view, light changed, noisy), in multiples of "
                    "32; at most 8x --spp per probe (a larger budget is capped); 0 = every probe traces --spp");
    cmd->add_option("--bounces", bounces, "surface interactions per path")->check(CLI::Range(1, 16));
    cmd->add_option("--seed", seed, "random seed (same seed, same result)");
    cmd->add_option("--w-min", wMin, "minimum temporal blend weight (0: a true mean until the history restarts or the scene changes)")
        ->check(CLI::Range(0.0f, 1.0f));
    cmd->add_option("--reject-sigmas", rejectSigmas,
                    "restart a probe's history when new estimates differ by more than this many standard errors (0 = never)")
        ->check(CLI::Range(0.0f, 1000.0f));
    cmd->add_option("--neighbour-history", neighbourHistory,
                    "the neighbours of a probe whose history restarts keep at most this many updates of theirs (0 = "
                    "off)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--change-history", changeHistory,
                    "when the scene's lights, materials or geometry change, every probe keeps at most this many "
                    "updates of history (0 = off)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--clamp", clamp, "max luminance of an indirect contribution (0 = off)")->check(CLI::Range(0.0f, 1e9f));
    cmd->add_flag("--relocate,!--no-relocate", relocate,
                  "move probes inside or too close to geometry (up to 45 % of a cell per axis) instead of only "
                  "switching them off (default on)");
    cmd->add_flag("--surface-probes-only,!--all-probes", surfaceProbesOnly,
                  "trace and send only the probes that light some surface (a triangle passes through the cells "
                  "around them); the others light no pixel and stay off (default on)");
  }
  renderer::UpdaterOptions options() const {
    renderer::UpdaterOptions o;
    o.samplesPerProbe = spp;
    o.maxBounces = bounces;
    o.seed = seed;
    o.minBlendWeight = wMin;
    o.rejectSigmas = rejectSigmas;
    o.neighbourHistory = neighbourHistory;
    o.changeHistory = changeHistory;
    o.indirectClamp = clamp;
    o.relocate = relocate;
    o.surfaceProbesOnly = surfaceProbesOnly;
    o.raysPerUpdate = raysPerUpdate;
    return o;
  }
};

// --area-lights on|off: emitters viewers shade themselves (scene/area_lights.h), left out of the
// probes traced here; the rule travels with the probes (file, stream, bus) so viewers follow it.
// A viewer of probes from a file or a server also takes "auto" (its default): light by the rule
// the probes state. on or off there must agree with the probes (a clear error otherwise: light
// would be counted twice or lost), and so must an --area-light-min given.
// Where probes are traced (view --probes live, serve, bake, demo) and --area-lights is not given:
// on, so emitters above --area-light-min are shaded by the viewers with soft shadows (a scene
// without such emitters has none either way). docs/MEASUREMENTS.md, "Defaults", has the figures.
inline constexpr char kAreaLightsDefault[] = "on";

struct AreaLightCli {
  std::string mode;
  float minFraction = 0.05f;
  CLI::Option* minOption = nullptr;
  AreaLightCli(std::string defaultMode = kAreaLightsDefault) : mode(std::move(defaultMode)) {}
  void add(CLI::App* cmd, bool follows = false) {
    std::vector<std::string> modes{"on", "off"};
    if (follows) modes.push_back("auto");
    cmd->add_option("--area-lights", mode,
                    "on: emissive surfaces become area lights the raster client shades with soft shadows, and the "
                    "probes traced here leave their direct light out" +
                        std::string(follows ? "; auto: as the probes say (live: " + std::string(kAreaLightsDefault) +
                                                  ")"
                                            : ""))
        ->check(CLI::IsMember(modes))
        ->capture_default_str();
    minOption = cmd->add_option("--area-light-min", minFraction,
                                "smallest share of the scene's emitted power an area light has")
                    ->check(CLI::Range(0.0f, 1.0f))
                    ->capture_default_str();
  }
  // Options for probes traced here ("auto": the default).
  scene::AreaLightOptions options() const {
    scene::AreaLightOptions o;
    o.enabled = (mode == "auto" ? std::string(kAreaLightsDefault) : mode) == "on";
    o.minPowerFraction = minFraction;
    return o;
  }
  // A viewer of probes made elsewhere (`source`): the options of their rule, or std::runtime_error
  // when what was asked for disagrees with it (session::followAreaLightRule).
  scene::AreaLightOptions follow(const AreaLightRule& rule, const std::string& source) const {
    return session::followAreaLightRule(rule, mode == "auto" ? std::nullopt : std::optional<bool>(mode == "on"),
                                        minOption && minOption->count() > 0 ? std::optional<float>(minFraction)
                                                                           : std::nullopt,
                                        source);
  }
};

// A bearer token given inline or in a file, surrounding whitespace dropped. A token that is empty
// after trimming is an error, never "no token": an empty file must not open a server to everyone.
inline std::string tokenFrom(const std::string& token, const std::string& file,
                             const std::string& fileOption = "--token-file") {
  const bool fromFile = !file.empty();
  const std::string raw = fromFile ? readTextFile(file) : token;
  const size_t first = raw.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    if (!fromFile && token.empty()) return {};  // none given
    throw std::runtime_error(fromFile ? fileOption + " " + file + " holds no token (empty or only whitespace)"
                                      : std::string("--token is empty or only whitespace"));
  }
  const std::string t = raw.substr(first, raw.find_last_not_of(" \t\r\n") + 1 - first);
  for (char c : t)  // it travels as an HTTP/2 header value
    if (c < 0x20 || c > 0x7e)
      throw std::runtime_error(std::string(fromFile ? fileOption + " " + file : "--token") +
                               ": the token must be printable ASCII on one line");
  return t;
}

// The link to the probe bus, never open by accident: a token (--nats-token-file) or NATS
// credentials (--nats-creds), or an explicit --nats-no-auth; TLS (--nats-tls, --nats-ca) or an
// explicit --nats-plaintext. Shared by serve --publish and edge; `needs` (optional) is the option
// without which these mean nothing.
struct BusOptions {
  std::string tokenFile, credsFile, caFile;
  bool noAuth = false, tls = false, plaintext = false;
  void add(CLI::App* cmd, CLI::Option* needs = nullptr) {
    CLI::Option* options[] = {
        cmd->add_option("--nats-token-file", tokenFile, "file holding the NATS server's authorization token")
            ->check(CLI::ExistingFile),
        cmd->add_option("--nats-creds", credsFile, "NATS credentials file (user JWT and NKey seed)")
            ->check(CLI::ExistingFile),
        cmd->add_flag("--nats-no-auth", noAuth, "connect to NATS without credentials (a trusted network only)"),
        cmd->add_flag("--nats-tls", tls, "connect to NATS over TLS (the system's roots unless --nats-ca)"),
        cmd->add_option("--nats-ca", caFile, "PEM file of the roots NATS's certificate must chain to (implies --nats-tls)")
            ->check(CLI::ExistingFile),
        cmd->add_flag("--nats-plaintext", plaintext, "connect to NATS without TLS (a trusted network only)")};
    options[0]->excludes(options[1]);
    options[2]->excludes(options[0])->excludes(options[1]);
    options[5]->excludes(options[3])->excludes(options[4]);
    if (needs)
      for (CLI::Option* o : options) o->needs(needs);
  }
  // Into `bus`, then checked (service::checkBusConfig): std::runtime_error naming the options.
  void apply(service::BusConfig& bus) const {
    std::string why;
    service::BusConfig where = bus;  // the URL and stream first, whatever the credentials
    where.noAuth = where.plaintext = true;
    if (!service::checkBusConfig(where, why)) throw std::runtime_error("--nats/--publish/--stream: " + why);
    bus.token = tokenFrom("", tokenFile, "--nats-token-file");
    bus.credsFile = credsFile;
    bus.noAuth = noAuth;
    bus.tls = tls || !caFile.empty();
    bus.caFile = caFile;
    bus.plaintext = plaintext;
    if (!bus.token.empty() && bus.token.find(' ') != std::string::npos)
      throw std::runtime_error("--nats-token-file " + tokenFile + ": the token must have no spaces");
    if (bus.token.empty() && bus.credsFile.empty() && !bus.noAuth)
      throw std::runtime_error("give --nats-token-file or --nats-creds, or --nats-no-auth to use a bus anyone who "
                               "reaches it may write to");
    if (!bus.tls && !bus.plaintext)
      throw std::runtime_error("give --nats-tls (or --nats-ca), or --nats-plaintext to use the bus without TLS");
    if (!service::checkBusConfig(bus, why)) throw std::runtime_error("--nats/--publish: " + why);
  }
};

// The listening side of a service: --listen, TLS (--tls-cert, --tls-key) or an explicit
// --plaintext, a bearer token (--token, --token-file) or an explicit --no-auth. Shared by the
// commands that serve.
struct ServerOptions {
  std::string listen = "127.0.0.1:50051", tlsCert, tlsKey, token, tokenFile;
  bool plaintext = false, noAuth = false;
  void add(CLI::App* cmd) {
    cmd->add_option("--listen", listen, "address to listen on (host:port)");
    cmd->add_option("--tls-cert", tlsCert, "PEM certificate file")->check(CLI::ExistingFile);
    cmd->add_option("--tls-key", tlsKey, "PEM private key file")->check(CLI::ExistingFile);
    cmd->add_flag("--plaintext", plaintext, "serve without TLS (trusted networks only)");
    CLI::Option* t = cmd->add_option("--token", token, "bearer token every call must present");
    CLI::Option* f =
        cmd->add_option("--token-file", tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
    CLI::Option* n =
        cmd->add_flag("--no-auth", noAuth, "serve without a token: anyone who reaches the port may subscribe");
    t->excludes(f);
    n->excludes(t)->excludes(f);
  }
  // The checked configuration: TLS or --plaintext, a non-empty token or --no-auth.
  service::ServerConfig config() const {
    service::ServerConfig sc;
    sc.listen = listen;
    sc.token = tokenFrom(token, tokenFile);
    sc.noAuth = noAuth;
    sc.plaintext = plaintext;
    if (!tlsCert.empty() || !tlsKey.empty()) {
      if (tlsCert.empty() || tlsKey.empty()) throw std::runtime_error("--tls-cert and --tls-key go together");
      sc.tlsCertPem = readTextFile(tlsCert);
      sc.tlsKeyPem = readTextFile(tlsKey);
    }
    if (sc.tlsCertPem.empty() && !sc.plaintext)
      throw std::runtime_error("give --tls-cert and --tls-key, or --plaintext to serve without TLS");
    if (sc.noAuth && !sc.token.empty()) throw std::runtime_error("--no-auth and a token contradict each other");
    if (!sc.noAuth && sc.token.empty())
      throw std::runtime_error(
          "give --token or --token-file, or --no-auth to let anyone who reaches the port subscribe");
    return sc;
  }
};

// How a started server is secured, for its banner: "TLS, token", "plaintext, token", or, loudly,
// that anyone may subscribe. A server without authentication also says so on stderr, once.
inline std::string describeSecurity(const service::ServerConfig& sc, const std::string& who, int port) {
  const std::string transport = sc.tlsCertPem.empty() ? "plaintext" : "TLS";
  if (!sc.noAuth) return transport + ", token";
  fmt::print(stderr,
             "{}: WARNING: no authentication (--no-auth): anyone who can reach port {} may subscribe; give --token "
             "or --token-file on any network you do not trust\n",
             who, port);
  std::fflush(stderr);
  return transport + ", NO AUTHENTICATION: anyone may subscribe";
}

// A client's connection to a server: --connect, --token (and --token-file), --tls-ca, --tls-name.
struct ConnectOptions {
  std::string connect, token, tokenFile, tlsCa, tlsName;
  void add(CLI::App* cmd, const std::string& what, bool required, bool withTokenFile) {
    CLI::Option* c = cmd->add_option("--connect", connect, what);
    if (required) c->required();
    cmd->add_option("--token", token, "bearer token");
    if (withTokenFile) cmd->add_option("--token-file", tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
    cmd->add_option("--tls-ca", tlsCa, "PEM root certificate to trust (enables TLS)")->check(CLI::ExistingFile);
    cmd->add_option("--tls-name", tlsName, "server name to check in its certificate");
  }
  // --connect may name several servers (edges), comma-separated: the client fails over between them.
  service::ClientConfig client(const std::string& name) const {
    service::ClientConfig cc;
    size_t start = 0;
    while (start <= connect.size()) {
      const size_t end = std::min(connect.find(',', start), connect.size());
      const std::string one = connect.substr(start, end - start);
      if (one.empty()) throw std::runtime_error("--connect '" + connect + "': an empty address in the list");
      cc.addresses.push_back(one);
      start = end + 1;
    }
    cc.address = cc.addresses.front();
    cc.token = tokenFrom(token, tokenFile);
    cc.name = name;
    if (!tlsCa.empty()) {
      cc.tls = true;
      cc.rootCertPem = readTextFile(tlsCa);
      cc.tlsServerName = tlsName;
    }
    return cc;
  }
};

// Scene, device, grid and tracer options together, for the commands that trace probes.
struct TracingOptions {
  SceneOptions scene;
  GpuOptions gpu;
  GridOptions grid;
  TracerOptions tracer;
  void add(CLI::App* cmd, bool withTracer = true) {
    scene.add(cmd);
    gpu.add(cmd);
    grid.add(cmd);
    if (withTracer) tracer.add(cmd);
  }
  // The tracer's options lit by `environment` (SceneOptions::environment, loaded once).
  renderer::UpdaterOptions updater(const std::shared_ptr<const renderer::Environment>& environment) const {
    renderer::UpdaterOptions o = tracer.options();
    o.environment = environment;
    return o;
  }
};

}  // namespace probecast::app
