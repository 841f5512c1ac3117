// `probecast demo`, the measurements its report adds: the pipeline benchmark and the stability
// suite on the demo's scene, and the stream against video of the viewers' own views.
#include <fmt/format.h>

#include <algorithm>
#include <functional>

#include "commands.h"
#include "demo.h"
#include "harness.h"
#include "progress.h"
#include "pipeline_bench.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "stability.h"
#include "video_bench.h"

namespace probecast::app {

// The pipeline benchmark (small) and the stability suite, written next to the report; returns
// their report sections.
std::string runSuites(const DemoOptions& o, const std::string& dir, const scene::Scene& finalScene, float finalT,
                      const ProbeGrid& grid, nlohmann::json& phases) {
  Progress progress("demo");
  const auto status = [&progress](const std::string& s) { progress.message(s); };
  auto phaseStart = DemoClock::now();
  bench::PipelineBenchOptions po;
  po.sceneSpec = o.scene;
  po.scene = finalScene;
  po.t = finalT;
  po.grid = grid;
  po.width = 128;
  po.height = 80;
  po.referenceSpp = o.referenceSpp;
  po.environment = o.sky;
  po.referenceCache = o.referenceCache;
  po.spps = {32, 128};
  po.bounces = {1, 4};
  po.deadzones = {0, 4, 16};
  po.streamFrames = 16;
  po.updates = 3;
  po.command = commandLine() + " (pipeline part)";
  po.progress = status;
  const bench::PipelineBenchResult pr = bench::runPipelineBench(po);
  writeTextFile(dir + "/pipeline.json", pr.json.dump(2) + "\n");
  writeTextFile(dir + "/pipeline_bytes.svg", pr.svgBytes);
  writeTextFile(dir + "/pipeline_update.svg", pr.svgUpdate);
  writeTextFile(dir + "/pipeline_repr.svg", pr.svgRepr);
  phases["pipeline"] = secondsSince(phaseStart);
  phaseStart = DemoClock::now();
  bench::StabilityOptions so;
  so.command = commandLine() + " (stability part)";
  so.progress = status;
  const bench::StabilityResult sr = bench::runStabilitySuite(so);
  writeTextFile(dir + "/stability.json", sr.json.dump(2) + "\n");
  phases["stability"] = secondsSince(phaseStart);
  progress.finish();
  return "\n## Speed against accuracy across the pipeline\n\n"
         "Same scene, same view (the light frozen where the demo stopped it), one run; the Pareto front of "
         "each chart is joined. Data: [pipeline.json](pipeline.json).\n\n"
         "![PSNR against wire bytes](pipeline_bytes.svg)\n\n![PSNR against update time](pipeline_update.svg)"
         "\n\n![PSNR against representation](pipeline_repr.svg)\n\n```\n" +
         pr.table +
         "```\n"
         "\n## Stability: where probe lighting fails, measured\n\nEach case is also a test "
         "(`ctest -L stability`). Data: [stability.json](stability.json).\n\n" +
         sr.markdown;
}

// The stream against video of the viewers' own views (bench video, one motion: the demo's scene at
// its rate, one second of frames), written next to the report; returns its report section. Without
// ffmpeg the section says so and the demo goes on.
std::string runVideoComparison(const DemoOptions& o, const DemoRun& run, const std::string& dir, nlohmann::json& report) {
  const auto phaseStart = DemoClock::now();
  Progress progress("demo");
  bench::VideoBenchOptions vo;
  vo.motions = {{"demo", o.scene, o.rate}};
  for (const DemoViewer& v : run.viewers) {
    const bool headset = v.viewSet == "stereo";
    vo.displays.push_back({headset ? "headset" : "lightfield", v.viewSet, v.width, v.height, /*followsHead=*/headset});
  }
  vo.headTrace = o.trace;
  const std::vector<int> x265Crfs{20, 28, 36, 44}, av1Crfs{20, 32, 44, 56, 63};
  for (const char* name : {"av1-444", "x265-444"}) {
    bench::VideoCodec codec;
    std::string error;
    orThrow(bench::parseVideoCodec(name, x265Crfs, av1Crfs, codec, error), error);
    vo.codecs.push_back(codec);
  }
  const ProbeGrid grid = run.grid;
  vo.grid = [grid](const scene::Scene&) { return grid; };
  vo.updater.samplesPerProbe = o.spp;
  vo.updater.environment = o.sky;
  vo.raster = bench::singleSampleRaster();
  vo.raster.environment = o.sky;
  vo.updater.areaLights = vo.raster.areaLights = o.areaLights.options();
  vo.context = o.device.context();
  bench::VideoStream stream;
  stream.name = o.repr;
  stream.repr = session::parseRepresentationOrThrow(o.repr);
  stream.encoder.deadzone = 1;
  stream.encoder.noiseScale = o.encoder.noiseScale;
  stream.encoder.refinementInterval = o.encoder.refinementInterval;
  vo.streams = {stream};
  vo.frames = 30;
  vo.warmup = 8;
  vo.ffmpeg = o.ffmpeg;
  vo.command = commandLine() + " (video part)";
  vo.progress = [&progress](const std::string& s) { progress.message(s); };
  std::string section = "\n## Against video of the same views\n\n";
  try {
    const bench::VideoBenchResult r = bench::runVideoBench(vo);
    progress.finish();
    writeTextFile(dir + "/video.json", r.json.dump(2) + "\n");
    for (const auto& [display, svg] : r.charts) {
      writeTextFile(dir + "/video_" + display + ".svg", svg);
      section += fmt::format("![{}: bytes against PSNR, the stream and each video codec](video_{}.svg)\n\n", display,
                             display);
    }
    section += fmt::format(
        "Both viewers' views drawn for one second at 30 frames per second from the updater's float probes "
        "(what a video server would encode) and from what a subscriber decodes from the {} stream; the float "
        "frames encoded with AV1 and x265 at 4:4:4 (low latency, GOP 30, a CRF sweep). {} Video bytes at the "
        "stream's PSNR against the float frames; ≥ or ≤ where the sweep does not reach it. Data: "
        "[video.json](video.json); `probecast bench video` measures more motions, displays and codecs.\n\n```\n{}```\n",
        o.repr,
        vo.headTrace ? fmt::format("The headset's camera {} ({}), the light-field display's stays still.",
                                   vo.headTrace->isPath() ? "follows a scripted path" : "turns as a recorded head turned",
                                   o.headTrace)
                     : std::string("Both cameras still."),
        r.table);
    report["video"] = r.json;
    fmt::print("demo: the stream against video of the same views\n{}", r.table);
  } catch (const std::runtime_error& e) {
    progress.finish();
    fmt::print("demo: the comparison with video was left out: {}\n", e.what());
    section += fmt::format("Left out: {}\n", e.what());
    report["video"] = {{"left_out", e.what()}};
  }
  report["phase_seconds"]["video"] = secondsSince(phaseStart);
  return section;
}

}  // namespace probecast::app
