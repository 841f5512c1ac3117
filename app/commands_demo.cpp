// `probecast demo`: the product end to end on one machine. A server traces builtin:cornell with a
// moving light and streams it over loopback gRPC; a stereo headset and a light-field display
// subscribe, re-render whenever new lighting arrives (direct light at the current light position,
// indirect light from the probes they hold), and the run ends with both compared against the
// reference path tracer. With --environment or --sky, the same sky lights the server's probes, shows
// behind the viewers' scene and lights the references. Writes images, charts, report.md and
// report.json to --out.
#include <filesystem>

#include "commands.h"
#include "demo.h"
#include "scene_options.h"

namespace probecast::app {

void addDemoCommand(CLI::App& app) {
  CLI::App* demo = app.add_subcommand("demo", "server + stereo and light-field viewers over loopback; writes out/");
  auto o = std::make_shared<DemoOptions>();
  demo->add_option("--out", o->out, "output folder");
  demo->add_option("--scene", o->scene, "scene the server lights: builtin:NAME or a glTF file (tests/data/scenes/cornell-animated/cornell-animated.gltf moves a cube and bends an arm)");
  demo->add_option("--seconds", o->seconds, "streaming time with the light moving")->check(CLI::Range(1.0, 3600.0));
  demo->add_option("--animate", o->rate,
                   "scene seconds per second while streaming (built-in scenes turn their light once per scene second; "
                   "a glTF file plays its animation)")
      ->check(CLI::Range(1e-6, 1000.0))
      ->capture_default_str();
  addSppOption(demo, o->spp, "updater samples per probe per update");
  o->grid.add(demo, false, 2, 64);
  addRepresentationOption(demo, o->repr, "representation streamed");
  demo->add_option("--light-field", o->lightField, "the light-field display's view set (lf:NxM or lfh:NxM)");
  demo->add_option("--settle-updates", o->settleUpdates, "updates with the light frozen before the comparison")
      ->check(CLI::Range(1, 10000));
  o->noise.add(demo);
  addReferenceSppOption(demo, o->referenceSpp, 1u << 16,
                        "samples per pixel of the reference images (two halves of different seeds)");
  demo->add_option("--reference-cache", o->referenceCache,
                   "where references are kept between runs (default $XDG_CACHE_HOME/probecast/references, else "
                   "~/.cache/probecast/references)");
  addVisibilityOption(demo, o->visibility);
  demo->add_option("--supersample", o->supersample,
                   "the viewers' N × N raster samples per pixel, averaged (as the references average each pixel)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(demo, o->msaa, o->anisotropy);
  o->areaLights.add(demo);
  o->device.add(demo);
  demo->add_flag("--skip-suites", o->skipSuites, "leave the pipeline benchmark and the stability suite out");
  demo->add_option("--video", o->video,
                   "on: the report sets the stream's bytes against AV1 and x265 video of both viewers' views at equal "
                   "PSNR (a short run of bench video; needs ffmpeg); off: left out")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  demo->add_option("--ffmpeg", o->ffmpeg, "the ffmpeg that --video runs")->capture_default_str();
  demo->add_option("--head-trace", o->headTrace,
                   "--video: the headset's camera turns as this recorded head turned (a trace file in the MMSys'18 "
                   "format, or builtin:mmsys18-user1: 10 s of a person in a headset), or follows a camera path "
                   "(probecast-camera-path 1, or builtin:walk-1m); none: a still camera. The light-field display "
                   "stays still")
      ->capture_default_str();
  o->environment.add(demo);
  demo->callback([o] {
    if (o->referenceSpp < 2)
      throw std::runtime_error("--reference-spp must be at least 2: a reference is two halves of different seeds");
    o->noise.apply(o->encoder, /*live=*/true);
    o->sky = o->environment.load();  // a bad map or sky fails here, before the server starts
    if (o->video == "on" && o->headTrace != "none") {  // and so does a bad head trace
      auto trace = std::make_shared<session::HeadTrace>();
      std::string error;
      if (!session::loadHeadTrace(o->headTrace, *trace, error)) throw std::runtime_error("--head-trace " + error);
      o->trace = trace;
    }
    DemoRun run;
    run.wallStart = DemoClock::now();
    std::filesystem::create_directories(o->out);
    runDemoSession(*o, run);
    writeDemoReport(*o, run);
  });
}

}  // namespace probecast::app
