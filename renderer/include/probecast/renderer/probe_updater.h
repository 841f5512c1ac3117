// The probe updater: path-traces a grid of L2 SH probes with the Vulkan ray-tracing pipeline.
//
// Per update, every active probe traces S paths over a spherical Fibonacci set rotated by a fresh
// random rotation; path radiance is projected ĉ = (4π/S) Σ L(ω) Y(ω) and blended into the probe
// with w = max(1/n, w_min). Each probe keeps running statistics of its per-update estimates (the
// luminance of c00 and of the three L1 coefficients): their variance σ² per update, hence the
// standard error of the blended history, published as ProbeVolume::noise. With history rejection
// (rejectSigmas = k > 0) a probe accumulates while each new estimate agrees with its history within
// k standard errors of the difference, and restarts from the new estimate (n = 1) when one does not
// (a light or an object moved); a short moving average catches changes smaller than one update's
// noise within a few updates. Probes whose rays see back faces too often are inside geometry: they
// move out of it when they can (UpdaterOptions::relocate, ProbeVolume::offsets), else they are
// inactive, get no rays and stay zero. With a ray budget (raysPerUpdate) an update traces probes by
// need instead — in a viewer's sight (setViewWeights), just restarted or held back, noisy — each
// with its own sample count, in multiples of the lanes; an estimate counts in the blend as its
// samples over samplesPerProbe updates, and a probe given none keeps its history and its noise. Output is the codec's ProbeVolume (probe_volume.h): 27
// floats per probe, coefficient-major, no Condon-Shortley phase; probe (x, y, z) at x + nx (y + ny z).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "probecast/codec/probe_volume.h"
#include "probecast/renderer/environment.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/area_lights.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

// The default grid of a scene: dims probes at the centres of the cells of a grid over its bounds.
ProbeGrid sceneGrid(const scene::Scene& scene, const std::array<uint32_t, 3>& dims);

struct UpdaterOptions {
  uint32_t samplesPerProbe = 128;  // rounded up to a multiple of 32; with a budget, one update's worth in the blend
  uint32_t maxBounces = 4;         // surface interactions per path
  float indirectClamp = 16.0f;     // max luminance of one contribution after the first bounce; 0 = off
  // w_min of the temporal blend, w = max(1/n, w_min); 0: a true mean until the history restarts or
  // the scene changes (changeHistory), so a still probe's noise keeps falling as 1/√n.
  float minBlendWeight = 0.0f;
  // History rejection: restart a probe whose new estimate (or short moving average) differs from
  // its history by more than this many standard errors of the difference; 0 = off (plain blend).
  float rejectSigmas = 4.0f;
  // With rejection: when a probe restarts and the restart is no lone blip of noise (another probe
  // of its 3×3×3 block restarts in the same update, or it moved by twice the rejection
  // threshold), its grid neighbours (one step along an axis) keep at most this many updates'
  // worth of history, so they follow a change they cannot yet tell from their own noise; 0 = off.
  float neighbourHistory = 8.0f;
  // With rejection: when setScene changes what lights the probes (its geometry, normals, texture
  // coordinates, textures, lights, materials or which material each triangle has; the environment
  // is fixed at construction), every probe keeps at most
  // this many updates' worth of history (as above: its value and variance stay, the
  // next estimates weigh in as after that many), so the volume follows a light that moves by less
  // than its noise per update instead of averaging the light's path; 0 = off.
  float changeHistory = 8.0f;
  uint32_t seed = 1;
  bool classify = true;            // mark probes inside geometry inactive
  // Mark inactive (idle) the probes that light no surface: no triangle passes through the cells
  // around them, so no viewer's pixel and no other probe reads them (probe_surfaces.h). They get
  // no rays and are never sent. false: every probe outside geometry is traced.
  bool surfaceProbesOnly = true;
  uint32_t classifySamples = 64;
  float backFaceThreshold = 0.25f; // inside geometry above this back-face hit ratio (RTXGI's rule)
  // Relocation (with classify): a probe inside geometry moves through the nearest back face its
  // classify rays see, one nearer than relocateClearance to a front face moves away from it, in up
  // to relocateRounds rounds of classify rays, each probe within relocateMaxShift of its cell per
  // axis. Only a probe still inside after that is inactive. Offsets are snapped to what viewers
  // reconstruct from the wire (probe_offsets.h), and probes are traced there.
  bool relocate = true;
  // When only the vertices of moving triangles move (an animated glTF scene, setScene), refit their
  // acceleration structures in place instead of building every one anew (vk_acceleration.h); off
  // rebuilds them all on every move (to compare).
  bool refitMovingGeometry = true;
  float relocateClearance = 0.2f;  // fraction of the smallest cell
  float relocateMaxShift = 0.45f;  // fraction of the cell on each axis
  uint32_t relocateRounds = 4;
  // Distant light: misses return it and next-event estimation importance-samples it (MIS with
  // the BSDF); none: misses are black. Probes see it directly, like any distant light.
  std::shared_ptr<const Environment> environment;
  bool environmentSampling = true;  // false: reach the environment by BSDF sampling only
  // Emitters the raster client lights itself (the same options as RasterOptions::areaLights):
  // probe rays see none of their emission directly; light bounced from them stays in.
  scene::AreaLightOptions areaLights;
  // Ray budget: primary paths per update, spent over the active probes by need (renderer/src/
  // ray_budget.h), rounded down to whole lanes (32); 0 = every active probe traces samplesPerProbe.
  uint64_t raysPerUpdate = 0;
  uint32_t maxSamplesPerProbe = 0;  // with a budget, per probe and update; 0 = 8 × samplesPerProbe (≤ 4096)
  float refreshShare = 0.1f;        // of the budget, one lane each to the probes traced longest ago
  float outOfViewWeight = 0.05f;    // need of a probe outside every view, against 1 inside one
};

struct UpdateStats {
  double milliseconds = 0.0;
  uint64_t paths = 0;        // primary samples traced
  uint64_t closestHitRays = 0;  // path segments (rays that need the closest hit)
  uint64_t shadowRays = 0;      // next-event rays (first hit ends them)
  uint32_t activeProbes = 0;
  uint64_t droppedSamples = 0;  // non-finite path samples replaced by 0 (a defect if ever nonzero)
  uint32_t restartedProbes = 0; // probes whose history was rejected this update
  uint32_t tracedProbes = 0;    // probes given rays (all active ones without a budget)
};

// The last classification (at construction and after each geometry change).
struct ClassifyStats {
  double milliseconds = 0.0;     // every classify round, rays and reduction
  uint32_t rounds = 0;           // classify dispatches
  uint32_t insideAtGrid = 0;     // probes inside geometry at their grid positions (inactive without relocation)
  uint32_t idle = 0;             // probes that light no surface (UpdaterOptions::surfaceProbesOnly), inactive
  uint32_t inactive = 0;         // probes left inactive (the idle ones included)
  uint32_t moved = 0;            // active probes with a nonzero offset
  double meanOffsetMetres = 0.0; // mean |offset| of the moved probes
  double maxOffsetCells = 0.0;   // largest |offset component| / cell
  // Moving geometry (setScene with the same triangles, moved): the probes within a cell of a moved
  // triangle, classified again where they stand (their offsets kept: a stream's epoch stays) and
  // restarted, so they follow the geometry within an update.
  uint32_t nearMoved = 0;
  bool partial = false;          // this classification was of the probes near moved geometry only
};

// How the updater's acceleration structures followed the geometry (setScene).
struct GeometryStats {
  uint32_t builds = 0;         // scenes built from scratch (the first one included)
  uint32_t refits = 0;         // moving runs refitted in place (only moving vertices moved)
  uint32_t refitRebuilds = 0;  // moving runs built again after kMaxRefits refits
  double lastMs = 0.0;         // the last geometry change: structures, surfaces and shading uploaded
};

class ProbeUpdater {
 public:
  ProbeUpdater(VulkanContext& context, const scene::Scene& scene, const ProbeGrid& grid,
               const UpdaterOptions& options = {});
  ~ProbeUpdater();
  ProbeUpdater(const ProbeUpdater&) = delete;
  ProbeUpdater& operator=(const ProbeUpdater&) = delete;

  // The animated scene: lights and materials are re-uploaded; changed normals, texture coordinates
  // or textures are uploaded again; changed geometry (positions, indices) rebuilds the acceleration
  // structures and reclassifies the probes.
  void setScene(const scene::Scene& scene);
  UpdateStats update();
  // How much each probe (grid order) matters to viewers, in [0, 1]: 1 inside some subscriber's
  // view, 0 outside every one (renderer/probe_interest.h). Empty: every probe counts as seen.
  // Used by the ray budget only. std::invalid_argument for a wrong size or a weight outside [0, 1].
  void setViewWeights(std::vector<float> weights);
  // Samples each probe (grid order) traced in the last update.
  const std::vector<uint32_t>& lastSamples() const;

  uint32_t probeCount() const;
  uint32_t updates() const;
  // The probes as traced so far (float samples; `updates` and `samplesPerProbe` filled in).
  const ProbeVolume& volume() const;
  const ProbeGrid& grid() const;
  const ClassifyStats& classifyStats() const;
  const GeometryStats& geometryStats() const;
  // Device memory this updater holds (buffers and acceleration structures), bytes: it grows with
  // the probe count, not with probes × samples.
  uint64_t deviceBytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::renderer
