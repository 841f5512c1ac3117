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

// Options that cannot run, refused before anything is traced.
void checkOptions(const MotionBenchOptions& o) {
  if (o.grid.count() == 0) throw std::invalid_argument("bench motion: the grid has no probes");
  if (o.moving == 0) throw std::invalid_argument("bench motion: --moving must be at least 1 update");
  if (!(o.step > 0.0) || !std::isfinite(o.step)) throw std::invalid_argument("bench motion: --step must be positive");
  if (!std::isfinite(o.start) || o.start < 0.0) throw std::invalid_argument("bench motion: --start must be >= 0");
}

// The scene time of every update: held at the start, a step per update while moving, then held
// where the motion stopped.
std::vector<double> sceneTimes(const MotionBenchOptions& o) {
  const uint32_t total = o.stillBefore + o.moving + o.stillAfter;
  std::vector<double> times(total);
  for (uint32_t k = 0; k < total; ++k) {
    const uint32_t m = k < o.stillBefore ? 0 : std::min(k - o.stillBefore + 1, o.moving);
    times[k] = o.start + o.step * m;
  }
  return times;
}

// A converged volume per scene time: a plain mean of 4 updates of referenceSamples paths, traced
// the first time that time is asked for.
class References {
 public:
  References(renderer::VulkanContext& context, const MotionBenchOptions& o) : context_(context), o_(o) {}
  const std::vector<float>& at(double t) {
    auto it = references_.find(t);
    if (it != references_.end()) return it->second;
    if (o_.progress) o_.progress(fmt::format("bench motion: reference at scene time {:.3f}", t));
    renderer::UpdaterOptions ro = o_.updater;
    ro.samplesPerProbe = o_.referenceSamples;
    ro.rejectSigmas = 0.0f;
    ro.raysPerUpdate = 0;
    ro.seed = o_.updater.seed + 7919;
    renderer::ProbeUpdater u(context_, session::loadSceneOrThrow(o_.sceneSpec, t), o_.grid, ro);
    for (int k = 0; k < 4; ++k) u.update();
    return references_.emplace(t, u.volume().probes).first->second;
  }

 private:
  renderer::VulkanContext& context_;
  const MotionBenchOptions& o_;
  std::map<double, std::vector<float>> references_;
};

// What every update works on: the scene at its current time, the updater tracing it, the stream
// encoder with the brick versions sent so far, the raster client and the converged volumes.
struct MotionRun {
  const MotionBenchOptions& o;
  const std::vector<double>& times;
  scene::Scene& current;
  renderer::ProbeUpdater& updater;
  StreamEncoder& encoder;
  std::vector<uint32_t>& versions;
  renderer::RasterRenderer& raster;
  References& references;
};

// What the bench measures: filled update by update, summed up by the report functions.
struct MotionMetrics {
  explicit MotionMetrics(size_t total) : errors(total) {}
  double fullClassifyMs = 0.0;
  nlohmann::json perUpdate = nlohmann::json::array();
  std::vector<double> errors, sceneMs, updateStillMs, updateMovingMs, visibilityMs, bytesMoving, bytesAfter;
  std::vector<double> stillNoise;
  std::vector<double> partialClassifyMs, accelMs, visibilityProbes;
};

// What moving the scene to update `k`'s time cost the updater: setScene's time and the probes
// classified again near what moved.
struct SceneMove {
  double setMs = 0.0;
  uint32_t near = 0;
};

SceneMove moveScene(MotionRun& run, uint32_t k, MotionMetrics& m) {
  SceneMove move;
  session::advanceScene(run.o.sceneSpec, run.times[k], run.current);
  const auto t0 = Clock::now();
  run.updater.setScene(run.current);
  move.setMs = msSince(t0);
  move.near = run.updater.classifyStats().nearMoved;
  m.sceneMs.push_back(move.setMs);
  m.partialClassifyMs.push_back(run.updater.classifyStats().milliseconds);
  m.accelMs.push_back(run.updater.geometryStats().lastMs);
  return move;
}

// The volume through the stream encoder: the bytes of the bricks whose version changed.
size_t sentBytes(MotionRun& run, const ProbeVolume& v) {
  run.encoder.update(v.probes.data(), v.active.data(), v.noise.empty() ? nullptr : v.noise.data(),
                     v.stillUpdates.empty() ? nullptr : v.stillUpdates.data());
  size_t bytes = 0;
  for (uint32_t b = 0; b < run.versions.size(); ++b)
    if (run.encoder.brickVersion(b) != run.versions[b]) {
      bytes += run.encoder.deltaSection(b).size();
      run.versions[b] = run.encoder.brickVersion(b);
    }
  return bytes;
}

// The raster client's visibility rebuild after the scene moved: its time and the probes whose
// depth cubes it drew again (zero when no geometry moved).
struct VisibilityRedraw {
  double ms = 0.0;
  uint32_t probes = 0;
};

VisibilityRedraw redrawVisibility(MotionRun& run, MotionMetrics& m) {
  VisibilityRedraw redraw;
  const uint64_t before = run.raster.timings().geometryMoves;
  run.raster.setShading(run.current);
  if (run.raster.timings().geometryMoves > before) {
    redraw.ms = run.raster.timings().visibilityRenderMs + run.raster.timings().visibilityMomentsMs;
    redraw.probes = run.raster.timings().visibilityProbesRedrawn;
  }
  m.visibilityMs.push_back(redraw.ms);
  m.visibilityProbes.push_back(redraw.probes);
  return redraw;
}

// Which recent time the volume matches best: its lag in updates (while moving).
int lagUpdates(MotionRun& run, uint32_t k, const ProbeVolume& v, double error) {
  int lag = 0;
  double best = error;
  for (int back = 1; back <= 4 && k >= static_cast<uint32_t>(back); ++back) {
    const double e =
        irradianceRmseRel(v.probes.data(), run.references.at(run.times[k - back]).data(), v.active.data(), run.o.grid.count());
    if (e < best) best = e, lag = back;
  }
  return lag;
}

// Update `k`: the scene moved to its time (if it changes), the probes updated, sent and drawn,
// and the volume set against the converged one.
void measureUpdate(MotionRun& run, uint32_t k, MotionMetrics& m) {
  const MotionBenchOptions& o = run.o;
  const std::vector<double>& times = run.times;
  const bool moved = k > 0 && times[k] != times[k - 1];
  const SceneMove move = moved ? moveScene(run, k, m) : SceneMove{};
  const renderer::UpdateStats st = run.updater.update();
  const ProbeVolume& v = run.updater.volume();
  (moved ? m.updateMovingMs : m.updateStillMs).push_back(st.milliseconds);
  const size_t bytes = sentBytes(run, v);
  const double perProbe = static_cast<double>(bytes) / o.grid.count();
  const VisibilityRedraw vis = moved ? redrawVisibility(run, m) : VisibilityRedraw{};
  run.raster.setProbes(v);
  m.errors[k] = irradianceRmseRel(v.probes.data(), run.references.at(times[k]).data(), v.active.data(), o.grid.count());
  const bool isMoving = k >= o.stillBefore && k < o.stillBefore + o.moving;
  if (isMoving) m.bytesMoving.push_back(perProbe);
  if (k >= o.stillBefore + o.moving) m.bytesAfter.push_back(perProbe);
  if (k + 1 < o.stillBefore && k >= o.stillBefore / 2) m.stillNoise.push_back(m.errors[k]);
  const int lag = isMoving ? lagUpdates(run, k, v, m.errors[k]) : 0;
  m.perUpdate.push_back({{"update", k + 1},
                         {"scene_time", times[k]},
                         {"phase", k < o.stillBefore ? "still" : (isMoving ? "moving" : "stopped")},
                         {"irradiance_error", m.errors[k]},
                         {"lag_updates", lag},
                         {"update_ms", st.milliseconds},
                         {"set_scene_ms", move.setMs},
                         {"probes_classified_again", move.near},
                         {"wire_bytes_per_probe", perProbe},
                         {"raster_visibility_ms", vis.ms},
                         {"raster_visibility_probes_redrawn", vis.probes}});
  if (o.progress)
    o.progress(fmt::format("bench motion: update {}/{} at {:.3f} s: error {:.4f}, {:.1f} ms + {:.1f} ms scene, "
                           "{:.2f} bytes/probe",
                           k + 1, times.size(), times[k], m.errors[k], st.milliseconds, move.setMs, perProbe));
}

// The figures over the phases: the still volume's error, the lag while moving, and when the error
// and the bytes settle after the stop.
struct MotionSummary {
  double noiseLevel = 0.0;
  int settle = -1;
  std::vector<double> movingLag, movingError;
  std::vector<double> settled;
};

MotionSummary summarise(const MotionBenchOptions& o, const MotionMetrics& m) {
  const uint32_t total = static_cast<uint32_t>(m.errors.size());
  MotionSummary s;
  // Lag after the stop: updates until the error is back within 1.25× the still volume's.
  s.noiseLevel = m.stillNoise.empty() ? m.errors[o.stillBefore ? o.stillBefore - 1 : 0] : mean(m.stillNoise);
  for (uint32_t k = o.stillBefore + o.moving; k < total; ++k)
    if (m.errors[k] <= 1.25 * s.noiseLevel) {
      s.settle = static_cast<int>(k - (o.stillBefore + o.moving) + 1);
      break;
    }
  for (uint32_t k = o.stillBefore; k < o.stillBefore + o.moving; ++k) {
    s.movingLag.push_back(m.perUpdate[k]["lag_updates"].get<int>());
    s.movingError.push_back(m.errors[k]);
  }
  // The bytes once the stream settles: the second half of the stopped phase.
  s.settled.assign(m.bytesAfter.begin() + static_cast<std::ptrdiff_t>(m.bytesAfter.size() / 2), m.bytesAfter.end());
  return s;
}

// The run's JSON: its settings, the summary and every update's figures.
nlohmann::json motionJson(const MotionBenchOptions& o, const renderer::ProbeUpdater& updater, const MotionMetrics& m,
                          const MotionSummary& s) {
  return {{"command", o.command},
          {"scene", o.sceneSpec},
          {"grid", {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]}},
          {"samples_per_probe", o.updater.samplesPerProbe},
          {"scene_step_per_update", o.step},
          {"updates", {{"still_before", o.stillBefore}, {"moving", o.moving}, {"still_after", o.stillAfter}}},
          {"reference", fmt::format("plain mean of 4 updates of {} paths per probe per scene time", o.referenceSamples)},
          {"still_error", s.noiseLevel},
          {"moving_error_median", median(s.movingError)},
          {"moving_lag_updates_mean", mean(s.movingLag)},
          {"updates_to_settle_after_stop", s.settle},
          {"update_ms_still_median", median(m.updateStillMs)},
          {"update_ms_moving_median", median(m.updateMovingMs)},
          {"set_scene_ms_median", median(m.sceneMs)},
          {"acceleration_structures", o.updater.refitMovingGeometry ? "moving runs refitted" : "rebuilt in full on every move"},
          {"acceleration_refits", updater.geometryStats().refits},
          {"acceleration_ms_median", median(m.accelMs)},
          {"acceleration_builds", updater.geometryStats().builds},
          {"classify_ms_full", m.fullClassifyMs},
          {"classify_ms_near_moved_median", median(m.partialClassifyMs)},
          {"wire_bytes_per_probe_moving_mean", mean(m.bytesMoving)},
          {"wire_bytes_per_probe_stopped_mean", mean(m.bytesAfter)},
          {"wire_bytes_per_probe_settled_mean", mean(s.settled)},
          {"raster_visibility_ms_median", median(m.visibilityMs)},
          {"raster_visibility_probes_redrawn_median", median(m.visibilityProbes)},
          {"per_update", m.perUpdate}};
}

// The summary as the table prints it.
std::string motionTable(const MotionBenchOptions& o, const MotionMetrics& m, const MotionSummary& s) {
  return fmt::format(
      "bench motion: {} on {}x{}x{} probes, {} spp, {:.3f} scene s per update\n"
      "  irradiance error: still {:.4f}, moving median {:.4f} (lag {:.2f} updates), settled {} updates after the stop\n"
      "  update ms: still {:.1f}, moving {:.1f} + setScene {:.1f} ({} {:.1f} ms; classify {:.1f} ms near moved vs {:.1f} "
      "ms all)\n"
      "  wire bytes per probe per update: moving {:.3f}, stopped {:.3f}, settled {:.3f}\n"
      "  raster visibility rebuild: {:.1f} ms per move ({:.0f} of {} probes' depth cubes drawn again)\n",
      o.sceneSpec, o.grid.dims[0], o.grid.dims[1], o.grid.dims[2], o.updater.samplesPerProbe, o.step, s.noiseLevel,
      median(s.movingError), mean(s.movingLag), s.settle, median(m.updateStillMs), median(m.updateMovingMs), median(m.sceneMs),
      o.updater.refitMovingGeometry ? "refit" : "full rebuild", median(m.accelMs), median(m.partialClassifyMs), m.fullClassifyMs,
      mean(m.bytesMoving), mean(m.bytesAfter), mean(s.settled),
      median(m.visibilityMs), median(m.visibilityProbes), o.grid.count());
}

}  // namespace

MotionBenchResult runMotionBench(const MotionBenchOptions& o) {
  checkOptions(o);
  renderer::VulkanContext context(o.context);
  scene::Scene current = session::loadSceneOrThrow(o.sceneSpec, o.start);
  if (!session::sceneMoves(o.sceneSpec, current))
    throw std::invalid_argument("bench motion: " + o.sceneSpec + " does not move (no animation)");
  const std::vector<double> times = sceneTimes(o);
  References references(context, o);

  renderer::ProbeUpdater updater(context, current, o.grid, o.updater);
  MotionMetrics metrics(times.size());
  metrics.fullClassifyMs = updater.classifyStats().milliseconds;
  StreamEncoder encoder(streamLayoutFor(o.grid, o.repr, 4), o.encoder);
  renderer::RasterRenderer raster(context, current, 64, 64);
  raster.setProbes(updater.volume());
  std::vector<uint32_t> versions(brickCount(encoder.layout()), 0);

  MotionRun run{o, times, current, updater, encoder, versions, raster, references};
  for (uint32_t k = 0; k < times.size(); ++k) measureUpdate(run, k, metrics);
  const MotionSummary summary = summarise(o, metrics);
  MotionBenchResult r;
  r.json = motionJson(o, updater, metrics, summary);
  r.table = motionTable(o, metrics, summary);
  return r;
}

}  // namespace probecast::bench
