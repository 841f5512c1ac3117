// `probecast bench` and its codec, stability, stream and edge subcommands; the others are in
// commands_bench_render.cpp (raster, scene, pipeline, environment), commands_bench_updater.cpp
// (update, motion, adaptive) and commands_bench_video.cpp (video).
#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "codec_bench.h"
#include "edge_bench.h"
#include "probecast/codec/probe_file.h"
#include "commands.h"
#include "commands_bench.h"
#include "progress.h"
#include "scene_options.h"
#include "stability.h"
#include "stream_bench.h"

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

}  // namespace

void addBenchCommands(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "measured speed and accuracy, machine-readable");
  bench->require_subcommand(1);
  addBenchCodec(bench);
  addBenchUpdate(bench);
  addBenchRaster(bench);
  addBenchPanel(bench);
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
