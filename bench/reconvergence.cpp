// Re-convergence of the in-view probes after a light jump, ray budget against brute force (reconvergence.h).
#include "reconvergence.h"

#include <cstring>
#include <span>

#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/raster_client.h"
#include "harness.h"
#include "probecast/session/scene_loading.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

std::vector<float> convergedAt(renderer::VulkanContext& context, const scene::Scene& s, const ProbeGrid& grid) {
  renderer::UpdaterOptions o;
  o.samplesPerProbe = 512;
  o.rejectSigmas = 0.0f;
  o.seed = 4242;
  renderer::ProbeUpdater u(context, s, grid, o);
  for (int k = 0; k < 16; ++k) u.update();
  return u.volume().probes;
}

int firstWithin(const std::vector<double>& error, double threshold) {
  for (size_t k = 0; k < error.size(); ++k)
    if (error[k] <= threshold) return static_cast<int>(k + 1);
  return -1;
}

}  // namespace

nlohmann::json ReconvergenceResult::json() const {
  return {{"rays_per_update", raysPerUpdate},
          {"in_view_probes", inViewProbes},
          {"active_probes", activeProbes},
          {"threshold_error", threshold},
          {"adaptive_updates", adaptiveUpdates},
          {"bruteforce_updates", bruteForceUpdates},
          {"reconvergence_vs_bruteforce", ratio},
          {"reconvergence_vs_bruteforce_at_most", ratio >= 0 ? ratio : ratioAtMost},
          {"adaptive_error_after_jump", adaptiveError},
          {"bruteforce_error_after_jump", bruteForceError}};
}

ReconvergenceResult measureReconvergence(renderer::VulkanContext& context, const ReconvergenceOptions& o) {
  const scene::Scene before = session::loadSceneOrThrow(o.sceneSpec, 0.0f);
  const scene::Scene after = session::loadSceneOrThrow(o.sceneSpec, 0.5f);
  const ProbeGrid grid = renderer::sceneGrid(before, o.dims);
  const std::vector<float> truthBefore = convergedAt(context, before, grid), truthAfter = convergedAt(context, after, grid);

  renderer::UpdaterOptions bo;
  bo.samplesPerProbe = o.samplesPerProbe;
  bo.minBlendWeight = 0.0f;
  bo.rejectSigmas = o.rejectSigmas;
  bo.neighbourHistory = o.neighbourHistory;
  bo.changeHistory = o.changeHistory;
  bo.seed = o.seed;
  renderer::ProbeUpdater brute(context, before, grid, bo);
  ReconvergenceResult r;
  const ProbeVolume& bv = brute.volume();
  r.activeProbes = 0;
  for (uint8_t a : bv.active) r.activeProbes += a ? 1u : 0u;
  r.raysPerUpdate = o.raysPerUpdate ? o.raysPerUpdate : static_cast<uint64_t>(r.activeProbes) * bv.samplesPerProbe;

  // The viewer: the scene's camera, narrowed; the probes whose support it sees are scored.
  renderer::CameraView camera = renderer::CameraView::fromScene(before);
  camera.yfov = o.viewYfov;
  View view{};
  {
    renderer::RasterRenderer raster(context, before, 64, 64, singleSampleRaster());
    const glm::mat4 vp = raster.viewProjection(camera);
    std::memcpy(view.viewProj, &vp[0][0], sizeof view.viewProj);
    view.eye[0] = camera.position.x, view.eye[1] = camera.position.y, view.eye[2] = camera.position.z;
  }
  const std::vector<float> weights = renderer::probeViewWeights(grid, bv.offsets, std::span<const View>(&view, 1));
  std::vector<uint8_t> inView(grid.count());
  for (uint32_t p = 0; p < grid.count(); ++p) {
    inView[p] = bv.active[p] && weights[p] > 0.0f ? 1 : 0;
    r.inViewProbes += inView[p];
  }

  renderer::UpdaterOptions ao = bo;
  ao.raysPerUpdate = r.raysPerUpdate;
  renderer::ProbeUpdater adaptive(context, before, grid, ao);
  adaptive.setViewWeights(weights);
  for (uint32_t k = 0; k < o.convergeUpdates; ++k) {
    brute.update();
    adaptive.update();
  }
  r.threshold = irradianceRmseRel(bv.probes.data(), truthBefore.data(), inView.data(), grid.count());
  brute.setScene(after);
  adaptive.setScene(after);
  for (uint32_t k = 0; k < o.afterUpdates; ++k) {
    brute.update();
    adaptive.update();
    r.bruteForceError.push_back(irradianceRmseRel(bv.probes.data(), truthAfter.data(), inView.data(), grid.count()));
    r.adaptiveError.push_back(
        irradianceRmseRel(adaptive.volume().probes.data(), truthAfter.data(), inView.data(), grid.count()));
  }
  r.adaptiveUpdates = firstWithin(r.adaptiveError, r.threshold);
  r.bruteForceUpdates = firstWithin(r.bruteForceError, r.threshold);
  if (r.adaptiveUpdates > 0 && r.bruteForceUpdates > 0) r.ratio = static_cast<double>(r.adaptiveUpdates) / r.bruteForceUpdates;
  else if (r.adaptiveUpdates > 0)
    r.ratioAtMost = static_cast<double>(r.adaptiveUpdates) / static_cast<double>(o.afterUpdates + 1);
  return r;
}

}  // namespace probecast::bench
