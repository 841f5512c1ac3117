// `probecast bench codec|update|raster|scene|pipeline|environment|stability|stream|edge|adaptive|motion|video`.
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "adaptive_bench.h"
#include "codec_bench.h"
#include "edge_bench.h"
#include "motion_bench.h"
#include "environment_bench.h"
#include "probecast/codec/probe_file.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/representation.h"
#include "commands.h"
#include "commands_bench.h"
#include "progress.h"
#include "scene_options.h"
#include "pipeline_bench.h"
#include "raster_bench.h"
#include "scene_bench.h"
#include "stability.h"
#include "stream_bench.h"
#include "update_bench.h"

namespace probecast::app {
namespace {

std::vector<bench::EnvMap> loadEnvMapDir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(dir + ": not a directory");
  std::vector<std::string> paths;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (entry.is_regular_file() && (ext == ".hdr" || ext == ".exr")) paths.push_back(entry.path().string());
  }
  if (ec) throw std::runtime_error(dir + ": " + ec.message());
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) throw std::runtime_error(dir + ": no .hdr or .exr environment maps");
  std::vector<bench::EnvMap> maps;
  for (const std::string& p : paths) {
    bench::EnvMap map;
    std::string error;
    orThrow(bench::loadEnvMap(p, map, error), error);
    maps.push_back(std::move(map));
  }
  return maps;
}

// `probecast bench codec`: codec size against accuracy and speed.
void addBenchCodec(CLI::App* bench) {
  CLI::App* codec = bench->add_subcommand("codec", "codec size against irradiance accuracy, speed, and temporal coding");

  struct Options {
    std::string envmaps, probes, json, chart;
    std::vector<int> deadzones{0, 1, 2, 4, 8};
    std::vector<float> errorBounds{0.02f, 0.05f, 0.1f};
    int frames = 60;
    int normals = 2048;
    int throughputProbes = 65536;
  };
  auto opt = std::make_shared<Options>();
  auto* envmaps = codec->add_option("--envmaps", opt->envmaps, "folder of equirect .hdr/.exr maps (top row +Y)")
                      ->check(CLI::ExistingDirectory);
  auto* probes = codec->add_option("--probes", opt->probes, "a baked probe volume file (probecast bake) to measure too")
                     ->check(CLI::ExistingFile);
  (void)envmaps;
  (void)probes;
  addJsonOption(codec, opt->json);
  codec->add_option("--chart", opt->chart, "write an SVG chart of error against bytes here");
  codec->add_option("--deadzones", opt->deadzones, "dead-zones (quantisation steps) for the temporal part")
      ->delimiter(',')
      ->check(CLI::Range(0, 127));
  codec->add_option("--error-bounds", opt->errorBounds,
                    "per-brick representation bounds for the temporal part (an l2 stream at dead-zone 1 each)")
      ->delimiter(',')
      ->check(CLI::Range(0.0001f, 10.0f));
  codec->add_option("--frames", opt->frames, "frames of the moving-light sequence")->check(CLI::Range(2, 100000));
  codec->add_option("--normals", opt->normals, "directions for the brute-force irradiance")->check(CLI::Range(16, 1 << 20));
  codec->add_option("--throughput-probes", opt->throughputProbes, "probes encoded and decoded for the speed figures")
      ->check(CLI::Range(1, 1 << 24));

  codec->callback([opt] {
    if (opt->envmaps.empty() && opt->probes.empty())
      throw std::runtime_error("give --envmaps DIR and/or --probes FILE");
    bench::CodecBenchOptions options;
    if (!opt->envmaps.empty()) options.maps = loadEnvMapDir(opt->envmaps);
    if (!opt->probes.empty()) {
      ProbeVolume volume;
      std::string error;
      orThrow(readProbeFile(opt->probes, volume, error), error);
      options.volumeName = opt->probes;
      options.volumeDims = {volume.grid.dims[0], volume.grid.dims[1], volume.grid.dims[2]};
      options.volumeProbes = std::move(volume.probes);
      options.volumeActive = std::move(volume.active);
    }
    options.deadzones = opt->deadzones;
    options.errorBounds = opt->errorBounds;
    options.frames = opt->frames;
    options.normals = opt->normals;
    options.throughputProbes = opt->throughputProbes;
    options.command = commandLine();
    options.progress = progressLine;
    const bench::CodecBenchResult r = bench::runCodecBench(options);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", opt->json, r.svg, opt->chart);
  });
}

// `probecast bench update`: updater speed, convergence, flicker.
void addBenchUpdate(CLI::App* bench) {
  CLI::App* update = bench->add_subcommand("update", "probe updater speed, convergence and flicker");
  auto ut = std::make_shared<TracingOptions>();
  struct UpdateOptions {
    std::string json, chart;
    uint32_t updates = 16, referenceSamples = 16384;
    std::vector<float> wMins{0.02f, 0.05f, 0.1f, 0.25f};
  };
  auto uo = std::make_shared<UpdateOptions>();
  ut->add(update);
  addJsonOption(update, uo->json);
  update->add_option("--chart", uo->chart, "write an SVG chart of error against time here");
  update->add_option("--updates", uo->updates, "updates per run")->check(CLI::Range(2, 10000));
  update->add_option("--reference-samples", uo->referenceSamples, "samples per probe of the reference")
      ->check(CLI::Range(1024u, 1u << 24));
  update->add_option("--w-mins", uo->wMins, "w_min values for the flicker runs")->delimiter(',')->check(CLI::Range(0.0f, 1.0f));
  update->callback([=] {
    bench::UpdateBenchOptions o;
    o.scene = ut->scene.load();
    o.grid = ut->grid.resolve(o.scene);
    o.updater = ut->updater(ut->scene.environment.load());
    o.context = ut->device.context();
    o.updates = uo->updates;
    o.referenceSamples = uo->referenceSamples;
    o.minBlendWeights = uo->wMins;
    o.command = commandLine();
    o.progress = progressLine;
    const bench::UpdateBenchResult r = bench::runUpdateBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", uo->json, r.svg, uo->chart);
  });
}

// What `bench raster` and `bench scene` share: the view size, probe updates, timed repeats, the
// reference (samples, cache folder) and the shadow maps.
struct RenderBenchCli {
  std::vector<uint32_t>* size;
  uint32_t* updates;
  uint32_t* repeats;
  uint32_t* referenceSpp;
  std::string* referenceCache;
  uint32_t* shadowMap;
  void add(CLI::App* cmd, const std::string& updatesWhat, const std::string& repeatsWhat) const {
    addSizeOption(cmd, *size, "size of each view WxH", 8, 4096);
    cmd->add_option("--updates", *updates, updatesWhat)->check(CLI::Range(1, 10000));
    cmd->add_option("--repeats", *repeats, repeatsWhat)->check(CLI::Range(1, 1000));
    addReferenceSppOption(cmd, *referenceSpp, 1u << 20, "samples per pixel of the reference (two halves of different seeds)");
    cmd->add_option("--reference-cache", *referenceCache,
                    "folder of cached references (default $XDG_CACHE_HOME/probecast/references or ~/.cache/...)");
    cmd->add_option("--shadow-map", *shadowMap, "shadow map texels per side")->check(CLI::Range(16, 8192));
  }
};

// `probecast bench raster`: raster client speed and accuracy.
void addBenchRaster(CLI::App* bench) {
  CLI::App* raster = bench->add_subcommand("raster", "raster client: ms per view for 1..48 views, PSNR/SSIM per representation");
  auto rt = std::make_shared<TracingOptions>();
  struct RasterOptions {
    std::string json, chart;
    std::vector<uint32_t> size{320, 200};
    bench::RasterBenchOptions bench;
    AreaLightCli areaLights{"off"};  // a benchmark's figures do not move with the product's default
  };
  auto ro = std::make_shared<RasterOptions>();
  rt->add(raster);
  raster->add_option("--views", ro->bench.viewSets, "view sets to time (mono, stereo, lf:NxM, lfh:NxM), comma-separated")
      ->delimiter(',');
  RenderBenchCli{&ro->size, &ro->bench.updates, &ro->bench.repeats, &ro->bench.referenceSpp, &ro->bench.referenceCache,
                 &ro->bench.raster.shadowMapSize}
      .add(raster, "probe updates before rendering", "timed renders per case (median)");
  addShadowCascadesOption(raster, ro->bench.raster.shadowCascades);
  raster->add_option("--supersample", ro->bench.raster.samplesPerSide,
                     "N × N raster samples per pixel, averaged (1 here, so the timings compare like with like; "
                     "the viewers default to 4)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(raster, ro->bench.raster.msaaSamples, ro->bench.raster.anisotropy);
  addVisibilityOption(raster, ro->bench.raster.visibility);
  ro->areaLights.add(raster);
  addJsonOption(raster, ro->json);
  raster->add_option("--chart", ro->chart, "write an SVG chart of PSNR against ms here (and *_views.svg)");
  raster->callback([=] {
    ro->bench.scene = rt->scene.load();
    ro->bench.grid = rt->grid.resolve(ro->bench.scene);
    ro->bench.updater = rt->updater(rt->scene.environment.load());  // the reference and background too
    ro->bench.updater.areaLights = ro->bench.raster.areaLights = ro->areaLights.options();
    ro->bench.context = rt->device.context();
    ro->bench.width = ro->size[0];
    ro->bench.height = ro->size[1];
    ro->bench.command = commandLine();
    ro->bench.progress = progressLine;
    const bench::RasterBenchResult r = bench::runRasterBench(ro->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", ro->json, r.svg, ro->chart);
    if (!ro->chart.empty()) {
      std::string views = ro->chart;
      const size_t dot = views.rfind(".svg");
      views = (dot == std::string::npos ? views : views.substr(0, dot)) + "_views.svg";
      writeTextFile(views, r.svgViews);
      fmt::print("wrote {}\n", views);
    }
  });
}

// `probecast bench scene`: the seeds' table for one scene against cached references.
void addBenchScene(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "scene", "one scene: update ms, raster ms per view, PSNR/SSIM per representation against a cached reference");
  auto st = std::make_shared<TracingOptions>();
  struct SceneCli {
    std::string json, chart;
    std::vector<uint32_t> size{160, 100};
    bench::SceneBenchOptions bench;
    AreaLightCli areaLights;
  };
  auto so = std::make_shared<SceneCli>();
  st->add(cmd);
  cmd->add_option("--views", so->bench.views, "mono, stereo or lf:NxM");
  RenderBenchCli{&so->size, &so->bench.updates, &so->bench.repeats, &so->bench.referenceSpp, &so->bench.referenceCache,
                 &so->bench.raster.shadowMapSize}
      .add(cmd, "probe updates (each timed)", "timed renders of the view set per representation (median)");
  cmd->add_option("--supersample", so->bench.raster.samplesPerSide,
                  "N × N raster samples per pixel, averaged (as the reference averages each pixel's area)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(cmd, so->bench.raster.msaaSamples, so->bench.raster.anisotropy);
  addVisibilityOption(cmd, so->bench.raster.visibility);
  so->areaLights.add(cmd);  // the reference sees every emitter either way, so the cached one still serves
  cmd->add_option("--reference-bounces", so->bench.referenceBounces, "surface interactions per reference path")
      ->check(CLI::Range(1, 16));
  cmd->add_option("--reference-seed", so->bench.referenceSeed, "seed of the first half-reference");
  cmd->add_option("--images", so->bench.imagesDir, "write PNGs of the reference and every representation here");
  cmd->add_option("--exposure", so->bench.exposure, "scale applied to the PNGs only")->check(CLI::Range(1e-6f, 1e6f));
  addJsonOption(cmd, so->json);
  cmd->add_option("--chart", so->chart, "write an SVG chart of PSNR against ms per view here");
  cmd->callback([=] {
    bench::SceneBenchOptions& o = so->bench;
    o.width = so->size[0];
    o.height = so->size[1];
    bench::checkSceneBenchOptions(o);  // before loading a large scene
    o.scene = st->scene.load();
    o.t = st->scene.t;
    o.grid = st->grid.resolve(o.scene);
    o.updater = st->updater(st->scene.environment.load());
    o.updater.areaLights = o.raster.areaLights = so->areaLights.options();
    o.context = st->device.context();
    o.command = commandLine();
    o.progress = progressLine;
    const bench::SceneBenchResult r = bench::runSceneBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", so->json, r.svg, so->chart);
  });
}

// `probecast bench motion`: probes, stream and raster client while geometry moves.
void addBenchMotion(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "motion", "an animated scene held, played and held again: error per scene time, lag, wire bytes, update and visibility ms");
  auto mt = std::make_shared<TracingOptions>();
  struct MotionCli {
    std::string json, repr = "zh3";
    int deadzone = 1;
    NoiseRuleCli noise;
    bench::MotionBenchOptions bench;
  };
  auto mo = std::make_shared<MotionCli>();
  mt->add(cmd);
  cmd->add_option("--step", mo->bench.step, "scene seconds per update while moving")->check(CLI::Range(1e-6, 1e6));
  cmd->add_option("--still-before", mo->bench.stillBefore, "updates held at --time before the motion")
      ->check(CLI::Range(2u, 10000u));
  cmd->add_option("--moving", mo->bench.moving, "updates while moving")->check(CLI::Range(1u, 10000u));
  cmd->add_option("--still-after", mo->bench.stillAfter, "updates held after the motion")->check(CLI::Range(1u, 10000u));
  cmd->add_option("--reference-samples", mo->bench.referenceSamples,
                  "paths per probe and update of each scene time's converged volume (4 updates)")
      ->check(CLI::Range(32u, 1u << 20));
  cmd->add_option("--repr", mo->repr, "stream representation (l1, zh3, l2)");
  cmd->add_option("--deadzone", mo->deadzone, "as serve's")->check(CLI::Range(0, 127));
  mo->noise.add(cmd);
  addJsonOption(cmd, mo->json);
  cmd->callback([=] {
    bench::MotionBenchOptions& o = mo->bench;
    o.sceneSpec = mt->scene.scene;
    o.start = mt->scene.t;
    const scene::Scene first = mt->scene.load();
    o.grid = mt->grid.resolve(first);
    o.updater = mt->updater(mt->scene.environment.load());
    o.context = mt->device.context();
    o.repr = session::parseRepresentationOrThrow(mo->repr);
    o.encoder.deadzone = mo->deadzone;
    mo->noise.apply(o.encoder, true);
    o.command = commandLine();
    o.progress = progressLine;
    const bench::MotionBenchResult r = bench::runMotionBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", mo->json, "", "");
  });
}

// `probecast bench pipeline`: PSNR against wire bytes, update time, representation.
void addBenchPipeline(CLI::App* bench) {
  CLI::App* pipeline = bench->add_subcommand("pipeline", "PSNR against wire bytes, update time and representation");
  auto pt = std::make_shared<TracingOptions>();
  struct PipelineCli {
    std::string json, chart;
    std::vector<uint32_t> size{160, 100};
    bench::PipelineBenchOptions bench;
  };
  auto po = std::make_shared<PipelineCli>();
  pt->add(pipeline, false);
  addSizeOption(pipeline, po->size, "image size WxH", 8, 4096);
  addReferenceSppOption(pipeline, po->bench.referenceSpp, 1u << 20);
  pipeline->add_option("--reference-cache", po->bench.referenceCache,
                       "folder of cached references (default $XDG_CACHE_HOME/probecast/references or ~/.cache/...)");
  pipeline->add_option("--spps", po->bench.spps, "samples per probe to try")->delimiter(',')->check(CLI::Range(1, 1 << 16));
  pipeline->add_option("--bounces", po->bench.bounces, "bounce limits to try")->delimiter(',')->check(CLI::Range(1, 16));
  pipeline->add_option("--deadzones", po->bench.deadzones, "dead-zones to try")->delimiter(',')->check(CLI::Range(0, 127));
  pipeline->add_option("--frames", po->bench.streamFrames, "moving-light frames streamed")->check(CLI::Range(2, 10000));
  addJsonOption(pipeline, po->json);
  pipeline->add_option("--chart", po->chart, "SVG prefix: writes PREFIX_bytes.svg, PREFIX_update.svg, PREFIX_repr.svg");
  pipeline->callback([=] {
    po->bench.sceneSpec = pt->scene.scene;
    po->bench.scene = pt->scene.load();
    po->bench.t = pt->scene.t;
    po->bench.grid = pt->grid.resolve(po->bench.scene);
    po->bench.context = pt->device.context();
    po->bench.environment = pt->scene.environment.load();
    po->bench.width = po->size[0];
    po->bench.height = po->size[1];
    po->bench.command = commandLine();
    po->bench.progress = progressLine;
    const bench::PipelineBenchResult r = bench::runPipelineBench(po->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", po->json, "", "");
    if (!po->chart.empty())
      for (const auto& [suffix, svg] : {std::pair{"_bytes.svg", &r.svgBytes}, std::pair{"_update.svg", &r.svgUpdate},
                                        std::pair{"_repr.svg", &r.svgRepr}}) {
        writeTextFile(po->chart + suffix, *svg);
        fmt::print("wrote {}{}\n", po->chart, suffix);
      }
  });
}

// `probecast bench environment`: environment importance sampling against BSDF-only sampling.
void addBenchEnvironment(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "environment", "reference tracer convergence under a small sun: environment importance sampling vs BSDF only");
  struct EnvironmentCli {
    SceneOptions scene;
    DeviceOptions device;
    std::string json, chart;
    std::vector<uint32_t> size{48, 32};
    bench::EnvironmentBenchOptions bench;
  };
  auto eo = std::make_shared<EnvironmentCli>();
  eo->scene.add(cmd);
  eo->device.add(cmd);
  addSizeOption(cmd, eo->size, "image size WxH", 4, 1024);
  addReferenceSppOption(cmd, eo->bench.referenceSpp, 1u << 20);
  cmd->add_option("--spps", eo->bench.spps, "samples per pixel to measure")->delimiter(',')->check(CLI::Range(1, 1 << 16));
  cmd->add_option("--bounces", eo->bench.maxBounces, "surface interactions per path")->check(CLI::Range(1, 16));
  addJsonOption(cmd, eo->json);
  cmd->add_option("--chart", eo->chart, "write an SVG chart of RMS error against spp here");
  cmd->callback([eo, cmd] {
    // Without --scene: a sunlit yard built in; without --environment or --sky: the built-in sunny sky.
    if (cmd->get_option("--scene")->count() > 0) {
      eo->bench.scene = eo->scene.load();
      eo->bench.camera = renderer::CameraView::fromScene(eo->bench.scene);
    } else {
      eo->bench.scene = bench::sunlitYard(eo->bench.camera);
    }
    eo->bench.environment = eo->scene.environment.given() ? eo->scene.environment.load() : bench::builtinSunSky();
    eo->bench.context = eo->device.context();
    eo->bench.width = eo->size[0];
    eo->bench.height = eo->size[1];
    eo->bench.command = commandLine();
    eo->bench.progress = progressLine;
    const bench::EnvironmentBenchResult r = bench::runEnvironmentBench(eo->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", eo->json, r.svg, eo->chart);
  });
}

// `probecast bench stability`: the stability suite.
void addBenchStability(CLI::App* bench) {
  CLI::App* stability = bench->add_subcommand("stability", "the stability suite: where probe lighting fails, measured");
  auto stabilityJson = std::make_shared<std::string>();
  addJsonOption(stability, *stabilityJson);
  stability->callback([stabilityJson] {
    bench::StabilityOptions so;
    so.command = commandLine();
    so.progress = progressLine;
    const bench::StabilityResult r = bench::runStabilitySuite(so);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", *stabilityJson, "", "");
  });
}

// `probecast bench stream`: the service under N subscribers.
void addBenchStream(CLI::App* bench) {
  CLI::App* stream = bench->add_subcommand(
      "stream", "the service under N subscribers on loopback: server and light load clients in processes of their own");
  struct StreamOptions {
    std::string json, chart, linkPacing = "on";
    GridOptions grid{{bench::kLightingGrid[0], bench::kLightingGrid[1], bench::kLightingGrid[2]}, {}};
    bench::StreamBenchOptions bench;
  };
  auto so = std::make_shared<StreamOptions>();
  stream->add_option("--subscribers", so->bench.subscribers, "subscriber counts to run, e.g. 1,10,100,1000")
      ->delimiter(',')
      ->check(CLI::Range(1, 5000));
  stream->add_option("--hz", so->bench.hz, "lighting updates per second")->check(CLI::Range(0.5, 240.0));
  stream->add_option("--seconds", so->bench.seconds, "measured time per subscriber count")->check(CLI::Range(2.0, 3600.0));
  stream->add_option("--budget", so->bench.budgetBytesPerSecond, "bytes per second per subscriber (0 = unlimited)");
  stream->add_option("--per-process", so->bench.subscribersPerLoadProcess, "subscribers per load process")
      ->check(CLI::Range(1, 5000));
  stream->add_option("--sample-every", so->bench.sampleEvery,
                     "1 in this many subscribers decodes in full and is checked bit for bit")
      ->check(CLI::Range(1, 5000));
  stream->add_option("--ack-interval", so->bench.ackIntervalMs,
                     "load clients ack the newest frame at most every this many ms, as ProbeClient does (0: every frame)")
      ->check(CLI::Range(0, 60000));
  stream->add_option("--link-pacing", so->linkPacing,
                     "on: load clients ack what the server asks for and it paces each to its link (as ProbeClient); "
                     "off: they do not, and it sends as fast as the transport takes frames")
      ->check(CLI::IsMember({"on", "off"}));
  so->grid.add(stream, false, 2, 256);  // the benchmark volume, probes 1 m apart
  stream->add_option("--edges", so->bench.edges,
                     "0: subscribers connect to the producer; N: through a nats-server and N edges")
      ->check(CLI::Range(0, 16));
  addRepresentationOption(stream, so->bench.repr, "l1, zh3h, zh3, l2 or fp16");
  addJsonOption(stream, so->json);
  stream->add_option("--chart", so->chart, "write an SVG chart here");
  stream->callback([so] {
    so->bench.command = commandLine();
    so->bench.progress = progressLine;
    so->bench.linkPacing = so->linkPacing == "on";
    for (int a = 0; a < 3; ++a) so->bench.grid[a] = static_cast<uint16_t>(so->grid.dims[a]);
    const bench::StreamBenchResult r = bench::runStreamBench(so->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", so->json, r.svg, so->chart);
    if (!r.failure.empty()) throw std::runtime_error("the stream was wrong: " + r.failure);
  });
}

// `probecast bench edge`: the probe bus and two edges against direct serving.
void addBenchEdge(CLI::App* bench) {
  CLI::App* edge = bench->add_subcommand("edge", "latency and failover through NATS and two edges, against direct");
  struct EdgeOptions {
    std::string json;
    bench::EdgeBenchOptions bench;
  };
  auto eo = std::make_shared<EdgeOptions>();
  edge->add_option("--clients", eo->bench.clients, "clients per phase (direct, then through the edges)")
      ->check(CLI::Range(1, 1000));
  edge->add_option("--hz", eo->bench.hz, "lighting updates per second")->check(CLI::Range(0.5, 240.0));
  edge->add_option("--seconds", eo->bench.seconds, "measured time per latency phase")->check(CLI::Range(1.0, 3600.0));
  edge->add_option("--kills", eo->bench.kills, "edges killed (SIGKILL) one after another")->check(CLI::Range(0, 100));
  addRepresentationOption(edge, eo->bench.repr, "l1, zh3h, zh3, l2 or fp16");
  addJsonOption(edge, eo->json);
  edge->callback([eo] {
    eo->bench.command = commandLine();
    eo->bench.progress = progressLine;
    const bench::EdgeBenchResult r = bench::runEdgeBench(eo->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", eo->json, "", "");
  });
}

// `bench adaptive`'s options: the bench's own and the command's.
struct AdaptiveOptions {
  std::string json, chart, repr = "zh3";
  GridOptions grid{{4, 4, 4}, {}};
  DeviceOptions device;
  bench::AdaptiveBenchOptions bench;
};

// The phases of the light and the traced rules' updaters.
void addAdaptivePhaseOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--spp", b.samplesPerProbe, "paths per probe per update")->check(CLI::Range(1u, 1u << 16));
  adaptive->add_option("--still", b.stillUpdates, "updates of each still phase")->check(CLI::Range(8u, 100000u));
  adaptive->add_option("--moving", b.movingUpdates, "updates with the light moving")->check(CLI::Range(1u, 100000u));
  adaptive->add_option("--light-step", b.lightStep, "t the light moves per update")->check(CLI::Range(0.0f, 1.0f));
  adaptive->add_option("--seed", b.seed, "seed of the traced rules' updaters (the spread between seeds is the bench's own noise)");
}

// The adaptive rule and the fixed ones it is compared with.
void addAdaptiveRuleOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--reject-sigmas", b.rejectSigmas, "k of the adaptive rule")->check(CLI::Range(0.5f, 1000.0f));
  adaptive->add_option("--neighbour-history", b.neighbourHistory,
                       "adaptive rule: neighbours of a restarted probe keep at most this many updates of history (0 = off)")
      ->check(CLI::Range(0.0f, 1e6f));
  adaptive->add_option("--change-history", b.changeHistory,
                       "adaptive rule: when the scene changes, every probe keeps at most this many updates of history "
                       "(0 = off)")
      ->check(CLI::Range(0.0f, 1e6f));
  adaptive->add_option("--w-mins", b.fixedWMins, "fixed rules to compare")->delimiter(',')->check(CLI::Range(0.0f, 1.0f));
}

// The streams each rule's volumes go through: the noise-aware one, the oracles, and all of them.
void addAdaptiveStreamOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--noise-scale", b.noiseScale, "c of the noise-aware stream")->check(CLI::Range(0.0f, 1000.0f));
  adaptive->add_option("--confirmations", b.confirmations,
                       "the noise-aware stream re-sends a probe once it has been beyond c sigma this many updates more")
      ->check(CLI::Range(0u, 1000u));
  adaptive->add_option("--oracle", b.oracleErrorRatios,
                       "also streams that know the truth and keep the held error within each of these x the full "
                       "stream's (about the least bytes for that error)")
      ->delimiter(',')
      ->check(CLI::Range(0.5f, 100.0f));
  adaptive->add_option("--oracle-exponents", b.oracleExponents,
                       "oracle streams weigh each probe's error by its energy to the minus these")
      ->delimiter(',')
      ->check(CLI::Range(0.0f, 2.0f));
  adaptive->add_option("--deadzone", b.deadzone, "dead-zone of every stream")->check(CLI::Range(0, 127));
  adaptive->add_flag("--surface-probes-only,!--all-probes", b.surfaceProbesOnly,
                     "trace and stream only the probes that light some surface (default on)");
  adaptive->add_option("--view-weights", b.viewWeights,
                       "the noise-aware stream holds probes the scored views show little of longer: none, footprint "
                       "(each probe's measured share of their pixels), surface (the views' surfaces and the probes "
                       "that light them, as a server can work them out) or lit (surface, weighed by the light the "
                       "volume holds, after gamma, at every update, blended over updates: what a producer does)")
      ->check(CLI::IsMember({"none", "footprint", "surface", "lit"}));
  adaptive->add_option("--refinement-interval", b.refinementInterval,
                       "noise-aware stream: refinements wait for the next update whose sequence is a multiple of this")
      ->check(CLI::Range(0u, 100000u));
}

// How images are scored, against what, and over how many seeds.
void addAdaptiveScoringOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--scored-updates", b.scoredUpdates,
                       "images scored at the last this many updates of each phase (the loss averaged over them)")
      ->check(CLI::Range(1u, 1000u));
  adaptive->add_option("--scored-views", b.scoredViews,
                       "views each scored image is made of: mono (the scene camera), stereo, lf:NxM or lfh:NxM "
                       "around it; one PSNR over all their pixels")
      ->check([](const std::string& text) {
        renderer::ViewSetSpec spec;
        std::string error;
        return renderer::parseViewSet(text, spec, error) ? std::string() : error;
      });
  adaptive->add_option("--truth-cache", b.truthCache,
                       "directory keeping the converged volumes images are scored against, between runs");
  adaptive->add_option("--stream-seeds", b.streamSeeds,
                       "the adaptive rule's streams are measured with this many seeds (--seed, --seed + 1, ...): "
                       "each noise-aware figure's mean and standard error")
      ->check(CLI::Range(1u, 1000u));
}

// The ray budget's re-convergence against brute force.
void addAdaptiveReconvergenceOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--rays-per-update", b.raysPerUpdate,
                       "rays per update of the budget and of brute force (0 = active probes x --spp)");
  adaptive->add_option("--view-yfov", b.viewYfov, "field of view (radians) of the viewer whose probes are scored")
      ->check(CLI::Range(0.01f, 3.1f));
  adaptive->add_flag("--reconvergence-only", b.reconvergenceOnly,
                     "measure only the re-convergence of the ray budget against brute force");
  adaptive->add_option("--reconvergence-updates", b.reconvergenceUpdates, "updates measured after the re-convergence jump")
      ->check(CLI::Range(1u, 100000u));
  adaptive->add_option("--reconvergence-seeds", b.reconvergenceSeeds,
                       "seeds the re-convergence is measured with (--seed, --seed + 1, ...); the summary is their median")
      ->check(CLI::Range(1u, 1000u));
}

// `probecast bench adaptive`: adaptive blending and the noise-aware stream against fixed w_min.
void addBenchAdaptive(CLI::App* bench) {
  CLI::App* adaptive = bench->add_subcommand(
      "adaptive", "history rejection and the noise-aware stream: bytes still/moving, flicker, lag, PSNR loss");
  auto ao = std::make_shared<AdaptiveOptions>();
  ao->device.add(adaptive);
  adaptive->add_option("--scene", ao->bench.sceneSpec, "an animated scene (t moves its light)");
  ao->grid.add(adaptive, /*withBounds=*/false, 2, 64);
  addAdaptivePhaseOptions(adaptive, ao->bench);
  addAdaptiveRuleOptions(adaptive, ao->bench);
  addAdaptiveStreamOptions(adaptive, ao->bench);
  addAdaptiveScoringOptions(adaptive, ao->bench);
  addRepresentationOption(adaptive, ao->repr, "l1, zh3h, zh3, l2 or fp16");
  addJsonOption(adaptive, ao->json);
  adaptive->add_option("--chart", ao->chart, "SVG prefix: writes PREFIX_bytes.svg and PREFIX_jump.svg");
  addAdaptiveReconvergenceOptions(adaptive, ao->bench);
  adaptive->callback([ao] {
    bench::AdaptiveBenchOptions o = ao->bench;
    o.dims = {ao->grid.dims[0], ao->grid.dims[1], ao->grid.dims[2]};
    o.repr = *parseRepresentation(ao->repr);
    o.context = ao->device.context();
    o.command = commandLine();
    o.progress = progressLine;
    const bench::AdaptiveBenchResult r = bench::runAdaptiveBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", ao->json, "", "");
    if (!ao->chart.empty() && !o.reconvergenceOnly)
      for (const auto& [suffix, svg] : {std::pair{"_bytes.svg", &r.svgBytes}, std::pair{"_jump.svg", &r.svgJump}})
        writeTextFile(ao->chart + suffix, *svg);
  });
}

}  // namespace

void addBenchCommands(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "measured speed and accuracy, machine-readable");
  bench->require_subcommand(1);
  addBenchCodec(bench);
  addBenchUpdate(bench);
  addBenchRaster(bench);
  addBenchScene(bench);
  addBenchPipeline(bench);
  addBenchEnvironment(bench);
  addBenchStability(bench);
  addBenchStream(bench);
  addBenchEdge(bench);
  addBenchAdaptive(bench);
  addBenchMotion(bench);
  addBenchVideo(bench);
}

}  // namespace probecast::app
