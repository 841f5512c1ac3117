// Probes while geometry moves (motion_bench.h).
#include "motion_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "probecast/renderer/raster_client.h"
#include "probecast/scene/animation.h"
#include "probecast/session/scene_loading.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace

MotionBenchResult runMotionBench(const MotionBenchOptions& o) {
  if (o.grid.count() == 0) throw std::invalid_argument("bench motion: the grid has no probes");
  if (o.moving == 0) throw std::invalid_argument("bench motion: --moving must be at least 1 update");
  if (!(o.step > 0.0) || !std::isfinite(o.step)) throw std::invalid_argument("bench motion: --step must be positive");
  if (!std::isfinite(o.start) || o.start < 0.0) throw std::invalid_argument("bench motion: --start must be >= 0");
  renderer::VulkanContext context(o.context);
  scene::Scene current = session::loadSceneOrThrow(o.sceneSpec, o.start);
  if (!session::sceneMoves(o.sceneSpec, current))
    throw std::invalid_argument("bench motion: " + o.sceneSpec + " does not move (no animation)");
  const uint32_t total = o.stillBefore + o.moving + o.stillAfter;
  std::vector<double> times(total);
  for (uint32_t k = 0; k < total; ++k) {
    const uint32_t m = k < o.stillBefore ? 0 : std::min(k - o.stillBefore + 1, o.moving);
    times[k] = o.start + o.step * m;
  }

  // A converged volume per scene time: a plain mean of 4 updates of referenceSamples paths.
  std::map<double, std::vector<float>> references;
  std::vector<uint8_t> referenceActive;
  const auto referenceAt = [&](double t) -> const std::vector<float>& {
    auto it = references.find(t);
    if (it != references.end()) return it->second;
    if (o.progress) o.progress(fmt::format("bench motion: reference at scene time {:.3f}", t));
    renderer::UpdaterOptions ro = o.updater;
    ro.samplesPerProbe = o.referenceSamples;
    ro.rejectSigmas = 0.0f;
    ro.raysPerUpdate = 0;
    ro.seed = o.updater.seed + 7919;
    renderer::ProbeUpdater u(context, session::loadSceneOrThrow(o.sceneSpec, t), o.grid, ro);
    for (int k = 0; k < 4; ++k) u.update();
    return references.emplace(t, u.volume().probes).first->second;
  };

  renderer::ProbeUpdater updater(context, current, o.grid, o.updater);
  const double fullClassifyMs = updater.classifyStats().milliseconds;
  StreamEncoder encoder(streamLayoutFor(o.grid, o.repr, 4), o.encoder);
  renderer::RasterRenderer raster(context, current, 64, 64);
  raster.setProbes(updater.volume());
  std::vector<uint32_t> versions(brickCount(encoder.layout()), 0);

  nlohmann::json perUpdate = nlohmann::json::array();
  std::vector<double> errors(total), sceneMs, updateStillMs, updateMovingMs, visibilityMs, bytesMoving, bytesAfter;
  std::vector<double> stillNoise;
  std::vector<double> partialClassifyMs, accelMs, visibilityProbes;
  for (uint32_t k = 0; k < total; ++k) {
    const bool moved = k > 0 && times[k] != times[k - 1];
    double setMs = 0.0;
    uint32_t near = 0;
    if (moved) {
      session::advanceScene(o.sceneSpec, times[k], current);
      const auto t0 = Clock::now();
      updater.setScene(current);
      setMs = msSince(t0);
      near = updater.classifyStats().nearMoved;
      sceneMs.push_back(setMs);
      partialClassifyMs.push_back(updater.classifyStats().milliseconds);
      accelMs.push_back(updater.geometryStats().lastMs);
    }
    const renderer::UpdateStats st = updater.update();
    const ProbeVolume& v = updater.volume();
    (moved ? updateMovingMs : updateStillMs).push_back(st.milliseconds);
    encoder.update(v.probes.data(), v.active.data(), v.noise.empty() ? nullptr : v.noise.data(),
                   v.stillUpdates.empty() ? nullptr : v.stillUpdates.data());
    size_t bytes = 0;
    for (uint32_t b = 0; b < versions.size(); ++b)
      if (encoder.brickVersion(b) != versions[b]) {
        bytes += encoder.deltaSection(b).size();
        versions[b] = encoder.brickVersion(b);
      }
    const double perProbe = static_cast<double>(bytes) / o.grid.count();
    double visMs = 0.0;
    uint32_t visProbes = 0;
    if (moved) {
      const uint64_t before = raster.timings().geometryMoves;
      raster.setShading(current);
      if (raster.timings().geometryMoves > before) {
        visMs = raster.timings().visibilityRenderMs + raster.timings().visibilityMomentsMs;
        visProbes = raster.timings().visibilityProbesRedrawn;
      }
      visibilityMs.push_back(visMs);
      visibilityProbes.push_back(visProbes);
    }
    raster.setProbes(v);
    errors[k] = irradianceRmseRel(v.probes.data(), referenceAt(times[k]).data(), v.active.data(), o.grid.count());
    const bool isMoving = k >= o.stillBefore && k < o.stillBefore + o.moving;
    if (isMoving) bytesMoving.push_back(perProbe);
    if (k >= o.stillBefore + o.moving) bytesAfter.push_back(perProbe);
    if (k + 1 < o.stillBefore && k >= o.stillBefore / 2) stillNoise.push_back(errors[k]);
    // Which recent time the volume matches best: its lag in updates (while moving).
    int lag = 0;
    if (isMoving) {
      double best = errors[k];
      for (int back = 1; back <= 4 && k >= static_cast<uint32_t>(back); ++back) {
        const double e =
            irradianceRmseRel(v.probes.data(), referenceAt(times[k - back]).data(), v.active.data(), o.grid.count());
        if (e < best) best = e, lag = back;
      }
    }
    perUpdate.push_back({{"update", k + 1},
                         {"scene_time", times[k]},
                         {"phase", k < o.stillBefore ? "still" : (isMoving ? "moving" : "stopped")},
                         {"irradiance_error", errors[k]},
                         {"lag_updates", lag},
                         {"update_ms", st.milliseconds},
                         {"set_scene_ms", setMs},
                         {"probes_classified_again", near},
                         {"wire_bytes_per_probe", perProbe},
                         {"raster_visibility_ms", visMs},
                         {"raster_visibility_probes_redrawn", visProbes}});
    if (o.progress)
      o.progress(fmt::format("bench motion: update {}/{} at {:.3f} s: error {:.4f}, {:.1f} ms + {:.1f} ms scene, "
                             "{:.2f} bytes/probe",
                             k + 1, total, times[k], errors[k], st.milliseconds, setMs, perProbe));
  }
  // Lag after the stop: updates until the error is back within 1.25× the still volume's.
  const double noiseLevel = stillNoise.empty() ? errors[o.stillBefore ? o.stillBefore - 1 : 0] : mean(stillNoise);
  int settle = -1;
  for (uint32_t k = o.stillBefore + o.moving; k < total; ++k)
    if (errors[k] <= 1.25 * noiseLevel) {
      settle = static_cast<int>(k - (o.stillBefore + o.moving) + 1);
      break;
    }
  std::vector<double> movingLag, movingError;
  for (uint32_t k = o.stillBefore; k < o.stillBefore + o.moving; ++k) {
    movingLag.push_back(perUpdate[k]["lag_updates"].get<int>());
    movingError.push_back(errors[k]);
  }
  // The bytes once the stream settles: the second half of the stopped phase.
  std::vector<double> settled(bytesAfter.begin() + static_cast<std::ptrdiff_t>(bytesAfter.size() / 2), bytesAfter.end());

  MotionBenchResult r;
  r.json = {{"command", o.command},
            {"scene", o.sceneSpec},
            {"grid", {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]}},
            {"samples_per_probe", o.updater.samplesPerProbe},
            {"scene_step_per_update", o.step},
            {"updates", {{"still_before", o.stillBefore}, {"moving", o.moving}, {"still_after", o.stillAfter}}},
            {"reference", fmt::format("plain mean of 4 updates of {} paths per probe per scene time", o.referenceSamples)},
            {"still_error", noiseLevel},
            {"moving_error_median", median(movingError)},
            {"moving_lag_updates_mean", mean(movingLag)},
            {"updates_to_settle_after_stop", settle},
            {"update_ms_still_median", median(updateStillMs)},
            {"update_ms_moving_median", median(updateMovingMs)},
            {"set_scene_ms_median", median(sceneMs)},
            {"acceleration_structures", o.updater.refitMovingGeometry ? "moving runs refitted" : "rebuilt in full on every move"},
            {"acceleration_refits", updater.geometryStats().refits},
            {"acceleration_ms_median", median(accelMs)},
            {"acceleration_builds", updater.geometryStats().builds},
            {"classify_ms_full", fullClassifyMs},
            {"classify_ms_near_moved_median", median(partialClassifyMs)},
            {"wire_bytes_per_probe_moving_mean", mean(bytesMoving)},
            {"wire_bytes_per_probe_stopped_mean", mean(bytesAfter)},
            {"wire_bytes_per_probe_settled_mean", mean(settled)},
            {"raster_visibility_ms_median", median(visibilityMs)},
            {"raster_visibility_probes_redrawn_median", median(visibilityProbes)},
            {"per_update", perUpdate}};
  r.table = fmt::format(
      "bench motion: {} on {}x{}x{} probes, {} spp, {:.3f} scene s per update\n"
      "  irradiance error: still {:.4f}, moving median {:.4f} (lag {:.2f} updates), settled {} updates after the stop\n"
      "  update ms: still {:.1f}, moving {:.1f} + setScene {:.1f} ({} {:.1f} ms; classify {:.1f} ms near moved vs {:.1f} "
      "ms all)\n"
      "  wire bytes per probe per update: moving {:.3f}, stopped {:.3f}, settled {:.3f}\n"
      "  raster visibility rebuild: {:.1f} ms per move ({:.0f} of {} probes' depth cubes drawn again)\n",
      o.sceneSpec, o.grid.dims[0], o.grid.dims[1], o.grid.dims[2], o.updater.samplesPerProbe, o.step, noiseLevel,
      median(movingError), mean(movingLag), settle, median(updateStillMs), median(updateMovingMs), median(sceneMs),
      o.updater.refitMovingGeometry ? "refit" : "full rebuild", median(accelMs), median(partialClassifyMs), fullClassifyMs, mean(bytesMoving), mean(bytesAfter), mean(settled),
      median(visibilityMs), median(visibilityProbes), o.grid.count());
  return r;
}

}  // namespace probecast::bench
