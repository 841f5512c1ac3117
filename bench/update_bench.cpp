#include "update_bench.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/sh.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"
#include "harness.h"

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

namespace {

// The reference: the plain mean of many samples (w_min = 0, no clamp).
struct ReferenceVolume {
  std::vector<float> probes;
  std::vector<uint8_t> active;
  uint32_t activeCount = 0;
  uint32_t samplesPerProbe = 0;  // in all
};

// One fixed blend weight: flicker once the mean has settled, and the error at the end.
struct FlickerRow {
  float wMin = 0;
  double flickerRel = 0, rmseRel = 0;
};

// What the bench measures: filled by the phases below, written by updateJson, updateTable and
// updateChart.
struct UpdateMetrics {
  ReferenceVolume reference;
  // Convergence, per update: its time, ray rates, error against the reference, time spent so far.
  std::vector<double> ms, raysPerS, closestPerS, shadowPerS, rmse, cumulativeMs;
  uint64_t deviceBytes = 0;
  std::vector<FlickerRow> flicker;
};

ReferenceVolume traceReference(renderer::VulkanContext& context, const UpdateBenchOptions& opt) {
  renderer::UpdaterOptions refOptions = opt.updater;
  refOptions.minBlendWeight = 0.0f;
  refOptions.rejectSigmas = 0.0f;
  refOptions.indirectClamp = 0.0f;
  refOptions.seed = opt.updater.seed + 1000;
  refOptions.samplesPerProbe = std::max(opt.updater.samplesPerProbe, 1024u);
  const uint32_t refUpdates = std::max(1u, opt.referenceSamples / refOptions.samplesPerProbe);
  renderer::ProbeUpdater reference(context, opt.scene, opt.grid, refOptions);
  for (uint32_t u = 0; u < refUpdates; ++u) {
    sayProgress(opt.progress,
                fmt::format("reference: update {}/{} ({} samples/probe)", u + 1, refUpdates, refOptions.samplesPerProbe));
    reference.update();
  }
  ReferenceVolume ref{reference.volume().probes, reference.volume().active, 0, refUpdates * refOptions.samplesPerProbe};
  for (uint8_t a : ref.active) ref.activeCount += a;
  return ref;
}

renderer::UpdaterOptions convergenceOptions(const UpdateBenchOptions& opt) {
  renderer::UpdaterOptions o = opt.updater;
  o.minBlendWeight = 0.0f;
  o.rejectSigmas = 0.0f;
  return o;
}

// Convergence: accumulate with w_min = 0 and measure error after every update.
void measureConvergence(renderer::VulkanContext& context, const UpdateBenchOptions& opt, UpdateMetrics& m) {
  const uint32_t count = opt.grid.count();
  renderer::ProbeUpdater updater(context, opt.scene, opt.grid, convergenceOptions(opt));
  double elapsed = 0;
  for (uint32_t u = 0; u < opt.updates; ++u) {
    const renderer::UpdateStats st = updater.update();
    elapsed += st.milliseconds;
    m.ms.push_back(st.milliseconds);
    const double seconds = st.milliseconds / 1000.0;
    m.raysPerS.push_back(static_cast<double>(st.closestHitRays + st.shadowRays) / seconds);
    m.closestPerS.push_back(static_cast<double>(st.closestHitRays) / seconds);
    m.shadowPerS.push_back(static_cast<double>(st.shadowRays) / seconds);
    m.rmse.push_back(irradianceRmseRel(updater.volume().probes.data(), m.reference.probes.data(),
                                       m.reference.active.data(), count));
    m.cumulativeMs.push_back(elapsed);
    sayProgress(opt.progress, fmt::format("update {}/{}: {:.1f} ms, {:.2f} M rays/s, error {:.2f}%", u + 1, opt.updates,
                                          st.milliseconds, m.raysPerS.back() / 1e6, 100 * m.rmse.back()));
  }
  m.deviceBytes = updater.deviceBytes();
}

// Flicker against w_min: relative irradiance change per update once the mean has settled.
FlickerRow measureFlicker(renderer::VulkanContext& context, const UpdateBenchOptions& opt, const ReferenceVolume& ref,
                          float w) {
  const uint32_t count = opt.grid.count();
  renderer::UpdaterOptions o = opt.updater;
  o.minBlendWeight = w;
  o.rejectSigmas = 0.0f;  // the fixed blend
  renderer::ProbeUpdater u(context, opt.scene, opt.grid, o);
  std::vector<float> previous;
  std::vector<double> changes;
  for (uint32_t k = 0; k < opt.updates; ++k) {
    u.update();
    if (!previous.empty() && k >= opt.updates / 2)
      changes.push_back(irradianceRmseRel(u.volume().probes.data(), previous.data(), ref.active.data(), count));
    previous.assign(u.volume().probes.data(), u.volume().probes.data() + count * 27);
  }
  const double f = changes.empty() ? 0.0 : session::median(changes);
  const double e = irradianceRmseRel(u.volume().probes.data(), ref.probes.data(), ref.active.data(), count);
  sayProgress(opt.progress, fmt::format("w_min {:.3f}: flicker {:.2f}% per update, error {:.2f}%", w, 100 * f, 100 * e));
  return {w, f, e};
}

nlohmann::json updateJson(const UpdateBenchOptions& opt, const std::string& device, const UpdateMetrics& m) {
  const renderer::UpdaterOptions conv = convergenceOptions(opt);
  nlohmann::json flicker = nlohmann::json::array();
  for (const FlickerRow& f : m.flicker) flicker.push_back({{"w_min", f.wMin}, {"flicker_rel", f.flickerRel}, {"rmse_rel", f.rmseRel}});
  return {{"command", opt.command},
          {"scene", opt.scene.name},
          {"triangles", opt.scene.triangleCount()},
          {"device", device},
          {"grid", {opt.grid.dims[0], opt.grid.dims[1], opt.grid.dims[2]}},
          {"active_probes", m.reference.activeCount},
          {"spp", conv.samplesPerProbe},
          {"bounces", conv.maxBounces},
          {"reference_samples_per_probe", m.reference.samplesPerProbe},
          {"ms_per_update", session::median(m.ms)},
          {"rays_per_s", session::median(m.raysPerS)},
          {"closest_hit_rays_per_s", session::median(m.closestPerS)},
          {"shadow_rays_per_s", session::median(m.shadowPerS)},
          {"rmse_rel_after_updates", m.rmse},
          {"cumulative_ms", m.cumulativeMs},
          {"flicker_rel", flicker},
          {"device_bytes", m.deviceBytes},
          {"peak_rss_mib", peakRssMiB()},
          {"error", "irradiance relative RMSE over active probes against the reference volume, exact over the sphere"},
          {"timing", "medians over updates; ray counts are counted in the shaders"}};
}

std::string updateTable(const UpdateBenchOptions& opt, const std::string& device, const UpdateMetrics& m) {
  const renderer::UpdaterOptions conv = convergenceOptions(opt);
  std::string table = fmt::format(
      "scene {} ({} triangles), grid {}x{}x{} ({} active), {} spp, {} bounces on {}\n"
      "ms/update {:.1f} | rays/s {:.2f} M (closest-hit {:.2f} M, shadow {:.2f} M) | device memory {:.1f} MiB | peak RSS "
      "{:.0f} MiB\n",
      opt.scene.name, opt.scene.triangleCount(), opt.grid.dims[0], opt.grid.dims[1], opt.grid.dims[2],
      m.reference.activeCount, conv.samplesPerProbe, conv.maxBounces, device, session::median(m.ms),
      session::median(m.raysPerS) / 1e6, session::median(m.closestPerS) / 1e6, session::median(m.shadowPerS) / 1e6,
      static_cast<double>(m.deviceBytes) / (1 << 20), peakRssMiB());
  table += "error after updates:";
  for (double e : m.rmse) table += fmt::format(" {:.2f}%", 100 * e);
  table += "\nw_min   flicker/update   error\n";
  for (const FlickerRow& f : m.flicker)
    table += fmt::format("{:<7g} {:>13.2f}% {:>9.2f}%\n", f.wMin, 100 * f.flickerRel, 100 * f.rmseRel);
  return table;
}

// Error against time spent: accumulating, and the final error of each w_min at the same time.
std::string updateChart(const UpdateBenchOptions& opt, const UpdateMetrics& m) {
  imaging::ChartSeries conv{"accumulating (w_min = 0)", {}, true};
  for (size_t i = 0; i < m.rmse.size(); ++i) conv.points.push_back({m.cumulativeMs[i], m.rmse[i], ""});
  imaging::ChartSeries flickerSeries{"final error per w_min", {}, false};
  const double elapsed = m.cumulativeMs.empty() ? 0.0 : m.cumulativeMs.back();
  for (const FlickerRow& f : m.flicker) flickerSeries.points.push_back({elapsed, f.rmseRel, fmt::format("w_min {:g}", f.wMin)});
  imaging::ChartSpec spec;
  spec.title = "probe updater: error against time spent (" + opt.scene.name + ")";
  spec.xLabel = "update time spent, ms";
  spec.yLabel = "irradiance relative RMSE vs reference";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = opt.command;
  return imaging::renderSvgChart(spec, {conv, flickerSeries});
}

}  // namespace

UpdateBenchResult runUpdateBench(const UpdateBenchOptions& opt) {
  renderer::VulkanContext context(opt.context);
  UpdateMetrics m;
  m.reference = traceReference(context, opt);
  measureConvergence(context, opt, m);
  for (float w : opt.minBlendWeights) m.flicker.push_back(measureFlicker(context, opt, m.reference, w));
  UpdateBenchResult r;
  r.json = updateJson(opt, context.deviceName(), m);
  r.table = updateTable(opt, context.deviceName(), m);
  r.svg = updateChart(opt, m);
  return r;
}

}  // namespace probecast::bench
