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
  demo->add_option("--scene", o->scene, "scene the server lights (built-in scenes animate their light)");
  demo->add_option("--seconds", o->seconds, "streaming time with the light moving")->check(CLI::Range(1.0, 3600.0));
  addSppOption(demo, o->spp, "updater samples per probe per update");
  o->grid.add(demo, false, 2, 64);
  addRepresentationOption(demo, o->repr, "representation streamed");
  demo->add_option("--light-field", o->lightField, "the light-field display's view set (lf:NxM or lfh:NxM)");
  demo->add_option("--settle-updates", o->settleUpdates, "updates with the light frozen before the comparison")
      ->check(CLI::Range(1, 10000));
  demo->add_option("--noise-scale", o->noiseScale,
                   "as serve: a probe is not re-sent while its change stays within this many standard errors of its "
                   "Monte Carlo noise (0 = off)")
      ->check(CLI::Range(0.0f, 1000.0f));
  addRefinementIntervalOption(demo, o->refinementInterval);
  addReferenceSppOption(demo, o->referenceSpp, 1u << 16, "samples per pixel of the reference images");
  addVisibilityOption(demo, o->visibility);
  demo->add_option("--supersample", o->supersample,
                   "the viewers' N × N raster samples per pixel, averaged (as the references average each pixel)")
      ->check(CLI::Range(1, 16));
  o->areaLights.add(demo);
  demo->add_flag("--skip-suites", o->skipSuites, "leave the pipeline benchmark and the stability suite out");
  o->environment.add(demo);
  demo->callback([o] {
    checkRefinementInterval(o->refinementInterval, o->noiseScale);
    o->sky = o->environment.load();  // a bad map or sky fails here, before the server starts
    DemoRun run;
    run.wallStart = DemoClock::now();
    std::filesystem::create_directories(o->out);
    runDemoSession(*o, run);
    writeDemoReport(*o, run);
  });
}

}  // namespace probecast::app
