#include "stability.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "probecast/codec/record.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "harness.h"
#include "stream_bench.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

// Each case's report: its figures in the JSON and its section of the markdown.

void reportFlickerLag(const std::vector<FlickerLag>& fl, StabilityResult& out) {
  out.markdown +=
      "### Temporal flicker against lag (builtin:cornell, 4³ probes, 32 samples per probe per update)\n\n"
      "| w_min | flicker per update | error before the jump | updates to recover after the light jumps "
      "|\n|---|---|---|---|\n";
  for (const FlickerLag& f : fl) {
    out.json["flicker_lag"].push_back({{"w_min", f.wMin},
                                       {"flicker_rel", f.flickerRel},
                                       {"error_before_jump", f.errorBeforeJump},
                                       {"error_after_jump", f.errorAfterJump},
                                       {"updates_to_recover", f.updatesToRecover}});
    out.markdown += fmt::format("| {:g} | {:.2f}% | {:.2f}% | {} |\n", f.wMin, 100 * f.flickerRel,
                                100 * f.errorBeforeJump,
                                f.updatesToRecover < 0 ? std::string("> 48") : std::to_string(f.updatesToRecover));
  }
}

void reportZh3Blending(const Zh3Blending& zb, StabilityResult& out) {
  out.json["zh3_blending"] = {{"stored_expanded_first", zb.storedExpandedFirst},
                              {"stored_naive", zb.storedNaive},
                              {"hallucinated_interpolate_first", zb.hallucinatedInterpolateFirst},
                              {"hallucinated_per_probe", zb.hallucinatedPerProbe},
                              {"l1", zb.l1}};
  out.markdown += fmt::format(
      "\n### ZH3 blended across probes with competing axes (worst irradiance error over the blend)\n\n"
      "| stored ZH3, expanded to SH3 first | stored ZH3, naive | hallucinated, interpolate first | "
      "hallucinated per probe | L1 alone |\n|---|---|---|---|---|\n| {:.2f}% | {:.2f}% | {:.2f}% | {:.2f}% | {:.2f}% "
      "|\n",
      100 * zb.storedExpandedFirst, 100 * zb.storedNaive, 100 * zb.hallucinatedInterpolateFirst,
      100 * zb.hallucinatedPerProbe, 100 * zb.l1);
}

void reportRinging(const std::vector<Ringing>& ringing, StabilityResult& out) {
  out.markdown +=
      "\n### SH ringing under a small strong light (L2 irradiance of a cap against the exact one)\n\n"
      "| cap half-angle | most negative / peak | normals negative | error unclamped | error clamped at 0 "
      "|\n|---|---|---|---|---|\n";
  for (const Ringing& rg : ringing) {
    out.json["ringing"].push_back({{"cap_deg", rg.capDeg},
                                   {"min_irradiance_rel", rg.minIrradianceRel},
                                   {"negative_fraction", rg.negativeFraction},
                                   {"rmse_rel_unclamped", rg.rmseRelUnclamped},
                                   {"rmse_rel_clamped", rg.rmseRelClamped}});
    out.markdown += fmt::format("| {:g}° | {:.2f}% | {:.1f}% | {:.2f}% | {:.2f}% |\n", rg.capDeg,
                                100 * rg.minIrradianceRel, 100 * rg.negativeFraction, 100 * rg.rmseRelUnclamped,
                                100 * rg.rmseRelClamped);
  }
}

void reportWallLeak(const WallLeak& wl, StabilityResult& out) {
  out.json["wall_leak"] = {{"probes", wl.probes},
                           {"inactive_probes", wl.inactiveProbes},
                           {"mean_error_rel_classified", wl.meanErrorRelClassified},
                           {"mean_error_rel_unclassified", wl.meanErrorRelUnclassified},
                           {"ray_savings", wl.raySavings}};
  out.markdown += fmt::format(
      "\n### Probes inside walls (builtin:thin-wall, 9×5×5 probes, seen from the lit room)\n\n"
      "Classification marks {} of {} probes inactive ({:.0f}% of probe rays not traced). Mean radiance "
      "against the reference: {:.1f}% off with classification, {:.1f}% off without (the dark leak).\n",
      wl.inactiveProbes, wl.probes, 100 * wl.raySavings, 100 * wl.meanErrorRelClassified,
      100 * wl.meanErrorRelUnclassified);
}

void reportNetworkFaults(const NetworkFaults& nf, StabilityResult& out) {
  out.json["network_faults"] = {{"lighting_kept_during_outage", nf.lightingKeptDuringOutage},
                                {"bit_exact_after_resume", nf.bitExactAfterResume},
                                {"seconds_to_bit_exact", nf.secondsToBitExact},
                                {"resume_bytes", nf.resumeBytes},
                                {"newcomer_bytes", nf.newcomerBytes},
                                {"slow_link_budget", nf.slowLinkBudget},
                                {"slow_link_seconds_to_bit_exact", nf.slowLinkSecondsToBitExact},
                                {"fast_seconds_to_bit_exact", nf.fastSecondsToBitExact},
                                {"latency_ms_p50", nf.latencyP50Ms},
                                {"latency_ms_p99", nf.latencyP99Ms},
                                {"slow_link_latency_ms_p50", nf.slowLinkLatencyP50Ms}};
  out.markdown += fmt::format(
      "\n### Network faults (loopback gRPC, 32×8×32 probes, zh3)\n\n"
      "A 2 s outage while the light moves: the viewer kept its last volume ({}); after the link came "
      "back it held the server's volume bit for bit ({}) in {:.2f} s, receiving {:.0f} bytes where a "
      "newcomer needed {:.0f}. A subscriber on a {:.0f} B/s link reached the same volume in {:.1f} s "
      "while an unlimited one took {:.2f} s. Produce → decoded latency with the light moving (50 updates/s): "
      "p50 {:.1f} ms, p99 {:.1f} ms unlimited; {:.0f} ms p50 on the slow link (versions wait for budget, "
      "and stale ones are skipped, not queued).\n",
      nf.lightingKeptDuringOutage ? "yes" : "no", nf.bitExactAfterResume ? "yes" : "no", nf.secondsToBitExact,
      nf.resumeBytes, nf.newcomerBytes, nf.slowLinkBudget, nf.slowLinkSecondsToBitExact, nf.fastSecondsToBitExact,
      nf.latencyP50Ms, nf.latencyP99Ms, nf.slowLinkLatencyP50Ms);
}

void reportExtremeInputs(const ExtremeInputs& ex, StabilityResult& out) {
  out.json["extreme_inputs"] = {
      {"black_max_abs", ex.blackMaxAbs}, {"nan_decoded_max_abs", ex.nanDecodedMaxAbs}, {"all_finite", ex.allFinite}};
  std::string bright;
  for (const auto& [scale, err] : ex.brightRelError) {
    out.json["extreme_inputs"]["bright_rel_error"].push_back({{"scale", scale}, {"rel_error", err}});
    bright += fmt::format("{}{:g}: {:.2f}%", bright.empty() ? "" : ", ", scale, 100 * err);
  }
  out.markdown += fmt::format(
      "\n### Extreme inputs through the codec\n\nBlack probes decode to at most {:g}. NaN and Inf "
      "radiance decode to finite values (largest {:g}); every decoded value finite: {}. Bright probes "
      "(l2 records, irradiance error by radiance scale) — {}: past the RGB9E5 ceiling of 65408 on the "
      "DC the error is bounded but large, so scenes brighter than that should be exposure-scaled "
      "before encoding.\n",
      ex.blackMaxAbs, ex.nanDecodedMaxAbs, ex.allFinite ? "yes" : "no", bright);
}

void reportSceneNeeds(const std::vector<SceneNeeds>& needs, StabilityResult& out) {
  std::string& md = out.markdown;
  for (const SceneNeeds& sn : needs) {
    out.json["scene_needs"].push_back({{"max_error", sn.maxError},
                                       {"probes", sn.probes},
                                       {"need_l1", sn.needL1},
                                       {"need_zh3", sn.needZh3},
                                       {"need_l2", sn.needL2},
                                       {"need_more", sn.needMore},
                                       {"bytes_all_l2", sn.bytesAllL2},
                                       {"bytes_smallest", sn.bytesSmallest},
                                       {"first_frame_bytes", sn.firstFrameBytes},
                                       {"static_frame_bytes", sn.staticFrameBytes},
                                       {"live_still_bytes_per_probe", sn.liveStillBytesPerProbe},
                                       {"live_moving_bytes_per_probe", sn.liveMovingBytesPerProbe}});
    if (sn.maxError == 0.05) md += "\n### No more than the scene needs (builtin:cornell, 8³ probes)\n";
    md += fmt::format(
        "\nFor an irradiance error of at most {:.0f}% per probe, {} active probes need: l1 {}, zh3 {}, l2 {}, more "
        "than l2 {} — {:.0f} "
        "bytes of records instead of {:.0f} for all-l2. A frame after publishing unchanged lighting is "
        "{:.0f} bytes (the first was {:.0f}).\n",
        100 * sn.maxError, sn.probes, sn.needL1, sn.needZh3, sn.needL2, sn.needMore, sn.bytesSmallest, sn.bytesAllL2,
        sn.staticFrameBytes, sn.firstFrameBytes);
    if (sn.maxError == 0.05)
      md += fmt::format(
          "\nThe live stream (zh3, dead-zone 1, every update published, headers included) costs {:.2f} bytes per "
          "probe per frame with the light still (Monte Carlo noise above the dead-zone) and {:.2f} with it moving, "
          "against 56 for a raw fp16 grid sent every frame.\n",
          sn.liveStillBytesPerProbe, sn.liveMovingBytesPerProbe);
  }
}

}  // namespace

StabilityResult runStabilitySuite(const StabilityOptions& o) {
  const auto say = [&](const std::string& line) { sayProgress(o.progress, line); };
  renderer::VulkanContext context{renderer::ContextOptions{}};
  StabilityResult out;
  out.json["command"] = o.command;
  out.json["codec_format_version"] = kFormatVersion;
  out.json["device"] = context.deviceName();
  say("stability: flicker and lag against w_min");
  reportFlickerLag(measureFlickerLag(context, {{0.02f, 0}, {0.05f, 0}, {0.1f, 0}, {0.25f, 0}}, 32, 48), out);
  say("stability: ZH3 blending");
  reportZh3Blending(measureZh3Blending(), out);
  say("stability: SH ringing");
  std::vector<Ringing> ringing;
  for (double cap : {2.0, 10.0, 30.0}) ringing.push_back(measureRinging(cap));
  reportRinging(ringing, out);
  say("stability: probes inside a thin wall");
  reportWallLeak(measureWallLeak(context), out);
  say("stability: network faults");
  reportNetworkFaults(measureNetworkFaults(), out);
  say("stability: extreme inputs");
  reportExtremeInputs(measureExtremeInputs(), out);
  say("stability: what the scene needs");
  reportSceneNeeds(measureSceneNeeds(context, {0.05, 0.10}), out);
  out.table = out.markdown;
  return out;
}

}  // namespace probecast::bench
