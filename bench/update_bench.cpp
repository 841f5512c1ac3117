#include "update_bench.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/sh.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {
namespace {

double peakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

}  // namespace

double irradianceRmseRel(const float* test, const float* reference, const uint8_t* active, uint32_t count) {
  double err = 0, energy = 0;
  for (uint32_t p = 0; p < count; ++p)
    if (!active || active[p])
      irradianceErrorEnergy(test + static_cast<size_t>(p) * kProbeFloats, reference + static_cast<size_t>(p) * kProbeFloats,
                            err, energy);
  return energy > 0 ? std::sqrt(err / energy) : 0.0;
}

double irradianceRmseRelPerProbe(const float* test, const float* reference, const uint8_t* active, uint32_t count) {
  double sum = 0;
  uint32_t probes = 0;
  for (uint32_t p = 0; p < count; ++p) {
    double err = 0, energy = 0;
    if (active && !active[p]) continue;
    irradianceErrorEnergy(test + static_cast<size_t>(p) * kProbeFloats, reference + static_cast<size_t>(p) * kProbeFloats,
                          err, energy);
    if (!(energy > 0)) continue;
    sum += err / energy;
    ++probes;
  }
  return probes > 0 ? std::sqrt(sum / probes) : 0.0;
}

UpdateBenchResult runUpdateBench(const UpdateBenchOptions& opt) {
  const auto say = [&](const std::string& s) {
    if (opt.progress) opt.progress(s);
  };
  renderer::VulkanContext context(opt.context);
  const uint32_t count = opt.grid.count();

  // Reference: the plain mean of many samples (w_min = 0, no clamp).
  renderer::UpdaterOptions refOptions = opt.updater;
  refOptions.minBlendWeight = 0.0f;
  refOptions.rejectSigmas = 0.0f;
  refOptions.indirectClamp = 0.0f;
  refOptions.seed = opt.updater.seed + 1000;
  refOptions.samplesPerProbe = std::max(opt.updater.samplesPerProbe, 1024u);
  const uint32_t refUpdates = std::max(1u, opt.referenceSamples / refOptions.samplesPerProbe);
  renderer::ProbeUpdater reference(context, opt.scene, opt.grid, refOptions);
  for (uint32_t u = 0; u < refUpdates; ++u) {
    say(fmt::format("reference: update {}/{} ({} samples/probe)", u + 1, refUpdates, refOptions.samplesPerProbe));
    reference.update();
  }
  const std::vector<float> ref = reference.volume().probes;
  const std::vector<uint8_t> active = reference.volume().active;
  uint32_t activeCount = 0;
  for (uint8_t a : active) activeCount += a;

  // Convergence: accumulate with w_min = 0 and measure error after every update.
  renderer::UpdaterOptions convOptions = opt.updater;
  convOptions.minBlendWeight = 0.0f;
  convOptions.rejectSigmas = 0.0f;
  renderer::ProbeUpdater updater(context, opt.scene, opt.grid, convOptions);
  std::vector<double> ms, raysPerS, closestPerS, shadowPerS, rmse, cumulativeMs;
  double elapsed = 0;
  for (uint32_t u = 0; u < opt.updates; ++u) {
    const renderer::UpdateStats st = updater.update();
    elapsed += st.milliseconds;
    ms.push_back(st.milliseconds);
    const double seconds = st.milliseconds / 1000.0;
    raysPerS.push_back(static_cast<double>(st.closestHitRays + st.shadowRays) / seconds);
    closestPerS.push_back(static_cast<double>(st.closestHitRays) / seconds);
    shadowPerS.push_back(static_cast<double>(st.shadowRays) / seconds);
    rmse.push_back(irradianceRmseRel(updater.volume().probes.data(), ref.data(), active.data(), count));
    cumulativeMs.push_back(elapsed);
    say(fmt::format("update {}/{}: {:.1f} ms, {:.2f} M rays/s, error {:.2f}%", u + 1, opt.updates, st.milliseconds,
                    raysPerS.back() / 1e6, 100 * rmse.back()));
  }
  const uint64_t deviceBytes = updater.deviceBytes();

  // Flicker against w_min: relative irradiance change per update once the mean has settled.
  nlohmann::json flicker = nlohmann::json::array();
  imaging::ChartSeries flickerSeries{"final error per w_min", {}, false};
  for (float w : opt.minBlendWeights) {
    renderer::UpdaterOptions o = opt.updater;
    o.minBlendWeight = w;
    o.rejectSigmas = 0.0f;  // the fixed blend
    renderer::ProbeUpdater u(context, opt.scene, opt.grid, o);
    std::vector<float> previous;
    std::vector<double> changes;
    for (uint32_t k = 0; k < opt.updates; ++k) {
      u.update();
      if (!previous.empty() && k >= opt.updates / 2)
        changes.push_back(irradianceRmseRel(u.volume().probes.data(), previous.data(), active.data(), count));
      previous.assign(u.volume().probes.data(), u.volume().probes.data() + count * 27);
    }
    const double f = changes.empty() ? 0.0 : session::median(changes);
    const double e = irradianceRmseRel(u.volume().probes.data(), ref.data(), active.data(), count);
    say(fmt::format("w_min {:.3f}: flicker {:.2f}% per update, error {:.2f}%", w, 100 * f, 100 * e));
    flicker.push_back({{"w_min", w}, {"flicker_rel", f}, {"rmse_rel", e}});
    flickerSeries.points.push_back({elapsed, e, fmt::format("w_min {:g}", w)});
  }

  UpdateBenchResult r;
  r.json = {{"command", opt.command},
            {"scene", opt.scene.name},
            {"triangles", opt.scene.triangleCount()},
            {"device", context.deviceName()},
            {"grid", {opt.grid.dims[0], opt.grid.dims[1], opt.grid.dims[2]}},
            {"active_probes", activeCount},
            {"spp", convOptions.samplesPerProbe},
            {"bounces", convOptions.maxBounces},
            {"reference_samples_per_probe", refUpdates * refOptions.samplesPerProbe},
            {"ms_per_update", session::median(ms)},
            {"rays_per_s", session::median(raysPerS)},
            {"closest_hit_rays_per_s", session::median(closestPerS)},
            {"shadow_rays_per_s", session::median(shadowPerS)},
            {"rmse_rel_after_updates", rmse},
            {"cumulative_ms", cumulativeMs},
            {"flicker_rel", flicker},
            {"device_bytes", deviceBytes},
            {"peak_rss_mib", peakRssMiB()},
            {"error", "irradiance relative RMSE over active probes against the reference volume, exact over the sphere"},
            {"timing", "medians over updates; ray counts are counted in the shaders"}};
  r.table = fmt::format(
      "scene {} ({} triangles), grid {}x{}x{} ({} active), {} spp, {} bounces on {}\n"
      "ms/update {:.1f} | rays/s {:.2f} M (closest-hit {:.2f} M, shadow {:.2f} M) | device memory {:.1f} MiB | peak RSS "
      "{:.0f} MiB\n",
      opt.scene.name, opt.scene.triangleCount(), opt.grid.dims[0], opt.grid.dims[1], opt.grid.dims[2], activeCount,
      convOptions.samplesPerProbe, convOptions.maxBounces, context.deviceName(), session::median(ms), session::median(raysPerS) / 1e6,
      session::median(closestPerS) / 1e6, session::median(shadowPerS) / 1e6, static_cast<double>(deviceBytes) / (1 << 20), peakRssMiB());
  r.table += "error after updates:";
  for (size_t i = 0; i < rmse.size(); ++i) r.table += fmt::format(" {:.2f}%", 100 * rmse[i]);
  r.table += "\nw_min   flicker/update   error\n";
  for (const auto& f : flicker)
    r.table += fmt::format("{:<7g} {:>13.2f}% {:>9.2f}%\n", f["w_min"].get<float>(), 100 * f["flicker_rel"].get<double>(),
                           100 * f["rmse_rel"].get<double>());

  imaging::ChartSeries conv{"accumulating (w_min = 0)", {}, true};
  for (size_t i = 0; i < rmse.size(); ++i) conv.points.push_back({cumulativeMs[i], rmse[i], ""});
  imaging::ChartSpec spec;
  spec.title = "probe updater: error against time spent (" + opt.scene.name + ")";
  spec.xLabel = "update time spent, ms";
  spec.yLabel = "irradiance relative RMSE vs reference";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = opt.command;
  r.svg = imaging::renderSvgChart(spec, {conv, flickerSeries});
  return r;
}

}  // namespace probecast::bench
