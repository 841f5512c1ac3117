// `probecast bake`: trace a probe grid with the Vulkan updater and write a probe volume file.
#include <fmt/format.h>

#include "commands.h"
#include "probecast/codec/probe_file.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/session/scene_state.h"
#include "scene_options.h"

namespace probecast::app {

void addBakeCommand(CLI::App& app) {
  CLI::App* bake = app.add_subcommand("bake", "path-trace a probe grid and write it (float SH + active mask)");
  auto tr = std::make_shared<TracingOptions>();
  auto out = std::make_shared<std::string>();
  auto updates = std::make_shared<uint32_t>(4);
  auto areaLights = std::make_shared<AreaLightCli>();
  tr->add(bake);
  areaLights->add(bake);
  bake->add_option("--updates", *updates, "updates to accumulate")->check(CLI::Range(1, 100000));
  bake->add_option("--out", *out, "probe volume file to write")->required();
  bake->callback([=] {
    const scene::Scene s = tr->scene.load();
    const auto env = tr->scene.environment.load();
    const service::ScenePackage package = tr->scene.package();  // the file names the scene it was traced in
    renderer::VulkanContext context(tr->device.context());
    const ProbeGrid g = tr->grid.resolve(s);
    renderer::UpdaterOptions uo = tr->updater(env);
    uo.areaLights = areaLights->options();
    renderer::ProbeUpdater updater(context, s, g, uo);
    fmt::print("bake: {} ({} triangles) on {}, grid {}x{}x{}, {} samples/probe, environment {}\n", s.name,
               s.triangleCount(), context.deviceName(), g.dims[0], g.dims[1], g.dims[2], tr->tracer.spp,
               env ? env->name : "none");
    const renderer::ClassifyStats& cs = updater.classifyStats();
    fmt::print("bake: {} of {} probes active ({} light no surface, {} inside geometry at grid positions, {} left "
               "inactive); relocation {}: {} moved, mean |offset| {:.3f} m, max {:.2f} cell, {} rounds, {:.1f} ms\n",
               g.count() - cs.inactive, g.count(), cs.idle, cs.insideAtGrid, cs.inactive, tr->tracer.relocate ? "on" : "off",
               cs.moved, cs.meanOffsetMetres, cs.maxOffsetCells, cs.rounds, cs.milliseconds);
    for (uint32_t u = 0; u < *updates; ++u) {
      const renderer::UpdateStats st = updater.update();
      fmt::print("bake: update {}/{}: {:.1f} ms, {} paths, {:.2f} M rays/s\n", u + 1, *updates, st.milliseconds, st.paths,
                 static_cast<double>(st.closestHitRays + st.shadowRays) / st.milliseconds / 1e3);
      if (st.droppedSamples > 0)
        fmt::print(stderr, "bake: update {}: {} non-finite path samples dropped\n", u + 1, st.droppedSamples);
    }
    ProbeVolume volume = updater.volume();
    volume.samplesPerProbe = tr->tracer.spp;  // as asked for (the updater traces it rounded up to 32s)
    volume.areaLights = session::areaLightRuleOf(uo.areaLights);  // so viewers light what the probes left out
    volume.scene = session::stampOf(package, tr->scene.t);
    fmt::print("bake: client area lights {}\n",
               uo.areaLights.enabled ? fmt::format("on (emitters of at least {} of the power)", uo.areaLights.minPowerFraction)
                                     : "off (the probes hold every emitter)");
    std::string error;
    orThrow(writeProbeFile(*out, volume, error), error);
    if (context.validationMessages() > 0)
      fmt::print(stderr, "bake: {} Vulkan validation messages\n", context.validationMessages());
    fmt::print("wrote {} ({} at scene time {})\n", *out, package.describe(), tr->scene.t);
  });
}

}  // namespace probecast::app
