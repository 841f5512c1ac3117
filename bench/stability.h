// The stability suite: each case measures one place where probe lighting is known to fail, and
// returns figures the tests bound and `probecast bench stability` and the demo report print.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/vulkan_context.h"

namespace probecast::bench {

// A temporal blending rule of the probe updater: w = max(1/n, w_min), with history rejection at
// `rejectSigmas` standard errors (0 = none: the fixed blend).
struct BlendRule {
  float wMin = 0;
  float rejectSigmas = 0;
};

// Temporal flicker at low samples per probe, and the lag it trades against: builtin:cornell
// (4³ probes) converges with the light at t = 0, then the light jumps to t = 0.5.
struct FlickerLag {
  float wMin = 0;
  float rejectSigmas = 0;
  double flickerRel = 0;         // median relative irradiance change per update, settled
  double errorBeforeJump = 0;    // relative irradiance RMSE against the converged t = 0 volume
  std::vector<double> errorAfterJump;  // against the converged t = 0.5 volume, per update after the jump
  int updatesToRecover = -1;     // first update after the jump within 1.5× errorBeforeJump (-1: never)
  // Against an updater started afresh on the t = 0.5 lighting with the same rule, per update: the
  // error no blending can avoid with these samples.
  std::vector<double> freshError;
  int updatesToFollow = -1;      // first update after the jump within 1.5× freshError (-1: never)
};
std::vector<FlickerLag> measureFlickerLag(renderer::VulkanContext& context, const std::vector<BlendRule>& rules,
                                          uint32_t samplesPerProbe, uint32_t updatesAfterJump);

// Blending ZH3 probes whose axes compete (light from +x in one, from +y in the other), over the
// blend weight w in [0, 1]: worst relative irradiance error against the blend of the L2 probes.
struct Zh3Blending {
  double storedExpandedFirst = 0;  // expand each to SH3, then blend (what the raster client uploads)
  double storedNaive = 0;          // blend L1 and zonal coefficients, re-derive the axis, then expand
  double hallucinatedInterpolateFirst = 0;  // blend L1, hallucinate (zh3h in the raster client)
  double hallucinatedPerProbe = 0;          // hallucinate per probe, then blend
  double l1 = 0;                            // L1 alone, for scale
};
Zh3Blending measureZh3Blending();

// SH ringing under a strong small light: a cap of half-angle `capDeg` (radiance such that the
// irradiance facing it is 1) projected to L2, against the exact irradiance on 4,096 normals.
struct Ringing {
  double capDeg = 0;
  double minIrradianceRel = 0;     // most negative L2 irradiance / largest exact irradiance
  double negativeFraction = 0;     // share of normals with negative L2 irradiance
  double rmseRelUnclamped = 0;     // relative RMSE of the L2 irradiance
  double rmseRelClamped = 0;       // the same after clamping at 0 (as the raster client does)
};
Ringing measureRinging(double capDeg);

// Probes inside a wall: builtin:thin-wall seen from the lit room, probe classification on and off,
// mean radiance of the raster client against the reference path tracer.
struct WallLeak {
  uint32_t probes = 0, inactiveProbes = 0;
  double meanErrorRelClassified = 0;  // |mean(raster) − mean(reference)| / mean(reference)
  double meanErrorRelUnclassified = 0;
  double raySavings = 0;              // share of probe rays not traced thanks to classification
};
WallLeak measureWallLeak(renderer::VulkanContext& context);

// Network faults over loopback gRPC: a 2 s outage while lighting changes, then resume; and a
// subscriber on a slow link (a byte budget).
struct NetworkFaults {
  bool lightingKeptDuringOutage = false;  // the volume held stayed the last good one (not black)
  bool bitExactAfterResume = false;
  double secondsToBitExact = 0;           // after the connection came back
  double resumeBytes = 0;                 // received after resuming
  double newcomerBytes = 0;               // a client joining at the same moment, holding nothing
  double slowLinkBudget = 0;              // bytes/s
  double slowLinkSecondsToBitExact = 0;
  double fastSecondsToBitExact = 0;       // unlimited subscriber, same moment
  // Produce → decoded latency of the frames applied (server and client share a clock here).
  double latencyP50Ms = 0, latencyP99Ms = 0;  // unlimited subscriber, light moving at 50 Hz
  double slowLinkLatencyP50Ms = 0;            // the slow-link subscriber: versions wait for budget
};
NetworkFaults measureNetworkFaults();

// Extreme inputs through the codec: black probes, very bright HDR, NaN radiance.
struct ExtremeInputs {
  double blackMaxAbs = 0;          // largest decoded value of an all-zero probe (should be 0)
  // Irradiance relative RMSE of a bright probe (l2 records) at peak radiance ≈ 2·scale, for scale
  // 1e2, 1e3, 1e4, 1e5, 1e6: the shared exponent of RGB9E5 holds the DC up to 65408.
  std::vector<std::pair<double, double>> brightRelError;
  double nanDecodedMaxAbs = 0;     // NaN radiance is replaced before encoding; what decodes
  bool allFinite = false;          // every decoded value finite
};
ExtremeInputs measureExtremeInputs();

// "No more than the scene needs": per probe of a traced builtin:cornell volume, the smallest
// representation whose irradiance error stays under `maxError` (relative to the probe's own
// irradiance), and the bytes not sent when nothing changes.
struct SceneNeeds {
  double maxError = 0;
  uint32_t probes = 0, needL1 = 0, needZh3 = 0, needL2 = 0, needMore = 0;
  double bytesAllL2 = 0, bytesSmallest = 0;     // a keyframe's worth of records
  double staticFrameBytes = 0;                  // a frame after publishing the same lighting again
  double firstFrameBytes = 0;
  // Bytes per probe per frame of the live stream (zh3, dead-zone 1, every update published), all
  // headers included: the light still (the updater keeps refining: Monte Carlo noise) and moving.
  double liveStillBytesPerProbe = 0, liveMovingBytesPerProbe = 0;
};
// One entry per error bound, all from one traced volume.
std::vector<SceneNeeds> measureSceneNeeds(renderer::VulkanContext& context, const std::vector<double>& maxErrors);

struct StabilityOptions {
  std::string command;
  std::function<void(const std::string&)> progress;
};
struct StabilityResult {
  nlohmann::json json;
  std::string table;
  std::string markdown;  // a report section
};
StabilityResult runStabilitySuite(const StabilityOptions& options);

}  // namespace probecast::bench
