// `probecast bench video`: its options, and what they name (motions, displays, video codecs, probe
// streams) read into the bench's own (bench/video_bench.h).
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>

#include "commands.h"
#include "commands_bench.h"
#include "harness.h"
#include "probecast/session/representation.h"
#include "progress.h"
#include "scene_options.h"
#include "video_bench.h"

namespace probecast::app {
namespace {

// What `bench video` is told on its command line beside the bench's own options.
struct VideoCli {
  std::string json, chart, moverScene, headTrace;
  int deadzone = 1;
  double moverRate = 0.5;
  AreaLightCli areaLights;
  std::vector<std::string> streams{"zh3", "l2", "l2:0"};
  std::vector<std::string> motions{"still=0", "slow=0.05", "fast=0.25"};
  std::vector<std::string> displays{"stereo=stereo@320x320", "quilt25=lf:5x5@128x128", "portrait48=lfh:8x6@96x128"};
  std::vector<std::string> codecs{"x265-444", "x265-420", "av1-444", "av1-420"};
  std::vector<int> x265Crfs{4, 12, 20, 28, 36, 44};
  std::vector<int> av1Crfs{8, 20, 32, 44, 56, 63};
  bench::VideoBenchOptions bench;
};

// The options, in the order --help lists them.
void addVideoOptions(CLI::App* cmd, TracingOptions& vt, VideoCli& vo) {
  vt.add(cmd);
  vo.areaLights.add(cmd);
  cmd->add_option("--motions", vo.motions,
                  "NAME=RATE for --scene, comma-separated: the scene clock's rate in scene seconds per second (0: still; "
                  "built-in scenes move their light once around per scene second)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--mover-scene", vo.moverScene, "an animated glTF file measured too, as motion 'mover'")
      ->check(CLI::ExistingFile);
  cmd->add_option("--head-trace", vo.headTrace,
                  "move every display's camera as a recorded head moved (a file of timestamp viewpoint w x y z per line, x "
                  "forward, z up: the MMSys'18 head-movement format; or builtin:mmsys18-user1, 10 s of one), with a neck "
                  "model; or along a scripted camera path (a file starting probecast-camera-path 1, lines of seconds "
                  "forward right up yaw pitch; or builtin:walk-1m); default: the camera is still");
  cmd->add_option("--truth-updates", vo.bench.truthUpdates,
                  "also score the streams and the videos against converged truth: each recorded moment's probes traced "
                  "from scratch for this many updates (0: only against the float-probe render)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--mover-rate", vo.moverRate, "the mover's clock rate, scene seconds per second")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--displays", vo.displays, "NAME=VIEWSET@WxH per display (views of WxH; VIEWSET as bench raster's --views)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--codecs", vo.codecs, "video codecs: x265-444, x265-420, av1-444, av1-420")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--x265-crf", vo.x265Crfs, "x265 CRFs to sweep")->delimiter(',')->check(CLI::Range(0, 51))->capture_default_str();
  cmd->add_option("--av1-crf", vo.av1Crfs, "AV1 CRFs to sweep")->delimiter(',')->check(CLI::Range(0, 63))->capture_default_str();
  cmd->add_option("--hz", vo.bench.hz, "probe updates per second")->check(CLI::Range(0.1, 240.0))->capture_default_str();
  cmd->add_option("--fps", vo.bench.fps, "display (and video) frames per second")->check(CLI::Range(1.0, 240.0))->capture_default_str();
  cmd->add_option("--frames", vo.bench.frames, "frames recorded per motion")->check(CLI::Range(2u, 100000u))->capture_default_str();
  cmd->add_option("--warmup", vo.bench.warmup, "probe updates before recording")->check(CLI::Range(0u, 10000u))->capture_default_str();
  cmd->add_option("--gop", vo.bench.gop, "video frames per keyframe interval")->check(CLI::Range(1u, 10000u))->capture_default_str();
  cmd->add_option("--preset", vo.bench.preset, "x265 preset")
      ->check(CLI::IsMember({"ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower", "veryslow", "placebo"}))
      ->capture_default_str();
  cmd->add_option("--exposure", vo.bench.exposure, "scale before the tone map (both pictures)")->check(CLI::Range(1e-6f, 1e6f));
  cmd->add_option("--ffmpeg", vo.bench.ffmpeg, "the ffmpeg to encode and decode with")->capture_default_str();
  cmd->add_option("--work-dir", vo.bench.workDir, "a folder of this run's own is made in here for the frames and bitstreams (default: the system's temporary folder); removed at the end unless --keep-files");
  cmd->add_flag("--keep-files", vo.bench.keepFiles, "keep the frames and bitstreams");
  cmd->add_option("--streams", vo.streams,
                  "probe stream configurations measured side by side, REPR[:NOISE_SCALE] (l1, zh3h, zh3, l2; the noise "
                  "rule's scale as serve's --noise-scale, 0 = off; default serve's)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--deadzone", vo.deadzone, "as serve's, for every stream")->check(CLI::Range(0, 127))->capture_default_str();
  addJsonOption(cmd, vo.json);
  cmd->add_option("--chart", vo.chart, "write an SVG chart of PSNR against bytes per second per display here (FILE, FILE_NAME.svg...)");
}

// --motions NAME=RATE, each on `sceneSpec`'s clock, then the --mover-scene as motion 'mover'.
void parseMotions(const VideoCli& vo, const std::string& sceneSpec, bench::VideoBenchOptions& o) {
  o.motions.clear();
  for (const std::string& m : vo.motions) {
    const size_t eq = m.find('=');
    double rate = 0;
    size_t used = 0;
    try {
      if (eq == std::string::npos || eq == 0) throw std::invalid_argument("");
      rate = std::stod(m.substr(eq + 1), &used);
    } catch (const std::exception&) {
      throw std::runtime_error("--motions: '" + m + "' is not NAME=RATE (e.g. slow=0.05)");
    }
    if (used != m.size() - eq - 1 || !std::isfinite(rate) || rate < 0 || rate > 100)
      throw std::runtime_error("--motions: '" + m + "': the rate must be a number from 0 to 100");
    o.motions.push_back({m.substr(0, eq), sceneSpec, rate});
  }
  if (!vo.moverScene.empty()) o.motions.push_back({"mover", vo.moverScene, vo.moverRate});
}

// --displays NAME=VIEWSET@WxH, then --codecs with the CRFs of each codec's family.
void parseDisplaysAndCodecs(const VideoCli& vo, bench::VideoBenchOptions& o) {
  o.displays.clear();
  for (const std::string& d : vo.displays) {
    bench::VideoDisplay display;
    std::string error;
    if (!bench::parseVideoDisplay(d, display, error)) throw std::runtime_error("--displays: " + error);
    o.displays.push_back(display);
  }
  o.codecs.clear();
  for (const std::string& c : vo.codecs) {
    bench::VideoCodec codec;
    std::string error;
    if (!bench::parseVideoCodec(c, vo.x265Crfs, vo.av1Crfs, codec, error)) throw std::runtime_error("--codecs: " + error);
    o.codecs.push_back(codec);
  }
}

// --streams REPR[:NOISE_SCALE], every one at --deadzone.
void parseStreams(const VideoCli& vo, bench::VideoBenchOptions& o) {
  o.streams.clear();
  for (const std::string& text : vo.streams) {
    bench::VideoStream st;
    st.name = text;
    const size_t colon = text.find(':');
    st.repr = session::parseRepresentationOrThrow(text.substr(0, colon));
    float scale = kNoiseScaleDefault;
    if (colon != std::string::npos) {
      size_t used = 0;
      try {
        scale = std::stof(text.substr(colon + 1), &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size() - colon - 1 || !std::isfinite(scale) || scale < 0 || scale > 1000)
        throw std::runtime_error("--streams: '" + text + "': the noise scale after ':' must be a number from 0 to 1000");
    }
    st.encoder.deadzone = vo.deadzone;
    st.encoder.noiseScale = scale;
    st.encoder.refinementInterval = scale > 0 ? kRefinementIntervalDefault : 0;
    o.streams.push_back(st);
  }
}

// The charts of the displays after the first (which goes to --chart itself): FILE_NAME.svg beside it.
void writeDisplayCharts(const std::string& chart, const bench::VideoBenchResult& r) {
  for (size_t k = 1; k < r.charts.size(); ++k) {
    const std::filesystem::path p(chart);
    const std::string path =
        (p.parent_path() / (p.stem().string() + "_" + r.charts[k].first + p.extension().string())).string();
    writeTextFile(path, r.charts[k].second);
    fmt::print("wrote {}\n", path);
  }
}

// The command's action: what it was told, read and checked in this order, then the bench and its
// outputs.
void runBenchVideo(const TracingOptions& vt, VideoCli& vo) {
  bench::VideoBenchOptions& o = vo.bench;
  parseMotions(vo, vt.scene.scene, o);
  parseDisplaysAndCodecs(vo, o);
  const auto grid = vt.grid;
  o.grid = [grid](const scene::Scene& s) { return grid.resolve(s); };
  if (!vo.headTrace.empty()) {
    auto trace = std::make_shared<session::HeadTrace>();
    std::string error;
    if (!session::loadHeadTrace(vo.headTrace, *trace, error)) throw std::runtime_error("--head-trace " + error);
    o.headTrace = trace;
  }
  o.updater = vt.updater(vt.scene.environment.load());
  o.raster = bench::singleSampleRaster();
  o.raster.environment = o.updater.environment;
  o.updater.areaLights = o.raster.areaLights = vo.areaLights.options();
  o.context = vt.device.context();
  parseStreams(vo, o);
  o.command = commandLine();
  o.progress = progressLine;
  const bench::VideoBenchResult r = bench::runVideoBench(o);
  writeBenchOutputs(r.table, r.json.dump(2) + "\n", vo.json, r.charts.empty() ? "" : r.charts[0].second, vo.chart);
  if (!vo.chart.empty()) writeDisplayCharts(vo.chart, r);
}

}  // namespace

// `probecast bench video`: the probe stream against streaming the same views as video.
void addBenchVideo(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "video", "the probe stream's bytes against x265 and AV1 video of the same views at equal PSNR, per display and motion");
  auto vt = std::make_shared<TracingOptions>();
  auto vo = std::make_shared<VideoCli>();
  addVideoOptions(cmd, *vt, *vo);
  cmd->callback([=] { runBenchVideo(*vt, *vo); });
}

}  // namespace probecast::app
