// bench adaptive's report: the JSON, the table and the charts of the rules, the light jump, the
// ray budget against brute force and the adaptive rule over seeds.
#include "adaptive_parts.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/probe_file.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"
#include "reconvergence.h"

namespace probecast::bench::adaptive {
namespace {

// A stream's figures: bytes per phase, the flicker of what it holds, and per scored moment its
// PSNR, probe error and PSNR loss against the full stream.
nlohmann::json streamJson(const Setup& s, const RuleRun& run, const Stream& st) {
  const AdaptiveBenchOptions& o = s.o;
  const size_t a = o.stillUpdates, b = o.stillUpdates + o.movingUpdates;
  nlohmann::json sj = {{"stream", st.name},
                       {"static_bytes_per_probe_frame", mean(st.bytesPerProbe, s.frames - o.stillUpdates / 2, s.frames)},
                       {"first_still_bytes_per_probe_frame", mean(st.bytesPerProbe, a / 2, a)},
                       {"moving_bytes_per_probe_frame", mean(st.bytesPerProbe, a, b)},
                       {"bytes_per_probe_frame", st.bytesPerProbe}};
  // Flicker of what a subscriber holds, over the last half of the second still phase: the
  // median as for the volume, and the mean, which counts the updates that change nothing.
  const std::vector<double> heldTail(st.heldChanges.end() - o.stillUpdates / 2, st.heldChanges.end());
  sj["held_flicker_rel_median"] = session::median(heldTail);
  sj["held_flicker_rel_mean"] = mean(heldTail, 0, heldTail.size());
  double worstLoss = 0;
  for (size_t m = 0; m < s.moments.size(); ++m) {
    // The loss is paired update by update against the stream that sends every change (same
    // noise in the volume, same truth), then averaged; its standard error says what it resolves.
    const std::vector<double>& mine = st.psnr[m];
    std::vector<double> loss(mine.size());
    for (size_t i = 0; i < mine.size(); ++i) loss[i] = run.streams[0].psnr[m][i] - mine[i];
    const double meanLoss = mean(loss, 0, loss.size());
    double var = 0;
    for (double x : loss) var += (x - meanLoss) * (x - meanLoss);
    const double se = loss.size() > 1 ? std::sqrt(var / static_cast<double>(loss.size() - 1) / static_cast<double>(loss.size())) : 0.0;
    const char* moment = s.moments[m].name;
    sj["psnr_db"][moment] = mean(mine, 0, mine.size());
    sj["probe_error_rel"][moment] = mean(st.probeError[m], 0, st.probeError[m].size());
    sj["probe_error_rel_per_probe"][moment] = mean(st.probeErrorEach[m], 0, st.probeErrorEach[m].size());
    sj["psnr_loss_db"][moment] = meanLoss;
    sj["psnr_loss_standard_error_db"][moment] = se;
    sj["psnr_loss_db_per_update"][moment] = loss;
    worstLoss = std::max(worstLoss, meanLoss);
  }
  sj["worst_psnr_loss_db"] = worstLoss;
  return sj;
}

}  // namespace

// The ray budget's part of the bench: its JSON and table lines. The first seed's jump is kept in
// full; every seed's ratio is listed and the summary takes their median.
void addReconvergence(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r) {
  ReconvergenceOptions ro;
  ro.sceneSpec = o.sceneSpec;
  ro.dims = o.dims;
  ro.samplesPerProbe = o.samplesPerProbe;
  ro.raysPerUpdate = o.raysPerUpdate;
  ro.viewYfov = o.viewYfov;
  ro.rejectSigmas = o.rejectSigmas;
  ro.neighbourHistory = o.neighbourHistory;
  ro.changeHistory = o.changeHistory;
  ro.afterUpdates = o.reconvergenceUpdates;
  const auto updates = [&](int n) { return n < 0 ? "> " + std::to_string(ro.afterUpdates) : std::to_string(n); };
  const auto ratioText = [](const ReconvergenceResult& rc) {
    return rc.ratio >= 0 ? fmt::format("{:.3f}", rc.ratio)
                         : rc.ratioAtMost >= 0 ? fmt::format("< {:.3f}", rc.ratioAtMost) : std::string("n/a");
  };
  std::vector<double> ratios;  // a seed whose budget never got there counts as infinitely slow
  for (uint32_t k = 0; k < std::max(o.reconvergenceSeeds, 1u); ++k) {
    ro.seed = o.seed + k;
    if (o.progress) o.progress(fmt::format("adaptive bench: ray budget against brute force, seed {}", ro.seed));
    const ReconvergenceResult rc = measureReconvergence(context, ro);
    const double ratio = rc.ratio >= 0 ? rc.ratio : rc.ratioAtMost >= 0 ? rc.ratioAtMost : HUGE_VAL;
    ratios.push_back(ratio);
    r.json["reconvergence_seeds"].push_back({{"seed", ro.seed},
                                             {"adaptive_updates", rc.adaptiveUpdates},
                                             {"bruteforce_updates", rc.bruteForceUpdates},
                                             {"reconvergence_vs_bruteforce_at_most", std::isfinite(ratio) ? ratio : -1.0}});
    if (k == 0) {
      r.json["reconvergence"] = rc.json();
      r.json["rays_per_update"] = rc.raysPerUpdate;
      r.json["summary"]["rays_per_update"] = rc.raysPerUpdate;
      r.table += fmt::format(
          "ray budget, light jump t 0 -> 0.5 after {} still updates, {} rays per update, {} of {} probes in view:\n",
          ro.convergeUpdates, rc.raysPerUpdate, rc.inViewProbes, rc.activeProbes);
    }
    r.table += fmt::format(
        "  seed {}: in-view error back to {:.4f} (brute force before the jump) after {} updates with the budget, {} "
        "brute force: ratio {}\n",
        ro.seed, rc.threshold, updates(rc.adaptiveUpdates), updates(rc.bruteForceUpdates), ratioText(rc));
  }
  const double median = session::median(ratios);
  r.json["summary"]["reconvergence_vs_bruteforce"] = std::isfinite(median) ? median : -1.0;
  r.json["summary"]["reconvergence_vs_bruteforce_at_most"] = std::isfinite(median) ? median : -1.0;
  r.json["summary"]["reconvergence_seeds"] = ratios.size();
  r.table += std::isfinite(median) ? fmt::format("  median ratio over {} seeds: {:.3f}\n", ratios.size(), median)
                                   : fmt::format("  median ratio over {} seeds: n/a\n", ratios.size());
}

// The noise-aware stream of the adaptive rule over seeds: each figure per seed, its mean, and the
// standard error of that mean (the spread between seeds is the bench's own noise).
void addSeedSummary(const std::vector<nlohmann::json>& bySeed, const AdaptiveBenchOptions& o, AdaptiveBenchResult& r) {
  const auto noiseStream = [](const nlohmann::json& rule) -> const nlohmann::json& { return rule["streams"][2]; };
  const std::vector<std::pair<std::string, std::function<double(const nlohmann::json&)>>> figures = {
      {"first_still_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["first_still_bytes_per_probe_frame"].get<double>(); }},
      {"moving_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["moving_bytes_per_probe_frame"].get<double>(); }},
      {"static_bytes_per_probe_frame", [](const nlohmann::json& s) { return s["static_bytes_per_probe_frame"].get<double>(); }},
      {"psnr_loss_db_still", [](const nlohmann::json& s) { return s["psnr_loss_db"]["still"].get<double>(); }},
      {"psnr_loss_db_moving", [](const nlohmann::json& s) { return s["psnr_loss_db"]["moving"].get<double>(); }},
      {"psnr_loss_db_still_again", [](const nlohmann::json& s) { return s["psnr_loss_db"]["still_again"].get<double>(); }},
      {"probe_error_rel_moving", [](const nlohmann::json& s) { return s["probe_error_rel"]["moving"].get<double>(); }},
      {"probe_error_rel_per_probe_moving",
       [](const nlohmann::json& s) { return s["probe_error_rel_per_probe"]["moving"].get<double>(); }}};
  nlohmann::json& out = r.json["stream_seeds"];
  out["seeds"] = nlohmann::json::array();
  for (const nlohmann::json& rule : bySeed) out["seeds"].push_back(rule["seed"]);
  out["rule"] = bySeed.front()["rule"];
  out["stream"] = noiseStream(bySeed.front())["stream"];
  for (const nlohmann::json& rule : bySeed)
    out["psnr_loss_db_per_update"].push_back(noiseStream(rule)["psnr_loss_db_per_update"]);
  r.table += fmt::format("noise-aware stream of the adaptive rule over seeds {}-{} (mean ± standard error):\n", o.seed,
                         o.seed + bySeed.size() - 1);
  for (const auto& [name, get] : figures) {
    std::vector<double> v;
    for (const nlohmann::json& rule : bySeed) v.push_back(get(noiseStream(rule)));
    const double m = mean(v, 0, v.size());
    double var = 0;
    for (double x : v) var += (x - m) * (x - m);
    const double se = std::sqrt(var / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
    out["figures"][name] = {{"per_seed", v}, {"mean", m}, {"standard_error", se}};
    r.table += fmt::format("  {:<36} {:>8.3f} ± {:.3f}  (", name, m, se);
    for (size_t i = 0; i < v.size(); ++i) r.table += fmt::format("{}{:.3f}", i ? " " : "", v[i]);
    r.table += ")\n";
  }
}

// The bench's settings in the JSON, and the table's head.
void writeHeader(const Setup& s, const Footprint& footprint, AdaptiveBenchResult& r) {
  const AdaptiveBenchOptions& o = s.o;
  nlohmann::json& j = r.json;
  j["command"] = o.command;
  j["codec_format_version"] = kFormatVersion;  // the stream bytes below are of this format
  j["device"] = s.context.deviceName();
  j["scene"] = s.first.name;
  j["grid"] = {o.dims[0], o.dims[1], o.dims[2]};
  j["samples_per_probe"] = o.samplesPerProbe;
  j["seed"] = o.seed;
  j["phases"] = {{"still", o.stillUpdates}, {"moving", o.movingUpdates}, {"still_again", o.stillUpdates},
                 {"light_step_t", o.lightStep}};
  j["representation"] = representationName(o.repr);
  j["surface_probes_only"] = o.surfaceProbesOnly;
  j["view_weights"] = o.viewWeights;
  if (!footprint.weights.empty())  // of the grid
    j["probes_that_change_no_pixel"] = std::count(footprint.weights.begin(), footprint.weights.end(), 0.0f);
  if (!footprint.match.is_null()) j["view_weight_estimates_vs_footprint"] = footprint.match;
  j["deadzone"] = o.deadzone;
  j["noise_scale"] = o.noiseScale;
  j["confirmations"] = o.confirmations;
  j["refinement_interval"] = o.refinementInterval;
  j["change_history"] = o.changeHistory;
  j["scored_views"] = o.scoredViews;
  j["metric"] = "flicker: median relative irradiance change per update over the last half of a still phase; PSNR of "
                "the raster view against the one from a converged float volume (plain gamma 2.2); probe error: relative "
                "irradiance RMSE of the held volume against that converged volume (probe_error_rel: pooled over the "
                "probes, so bright ones dominate; probe_error_rel_per_probe: each probe relative to its own energy, "
                "RMS over the probes)";
  r.table = fmt::format("adaptive bench: {} {}x{}x{} probes, {} spp, {}, dead-zone {}, on {}\n", s.first.name, o.dims[0],
                        o.dims[1], o.dims[2], o.samplesPerProbe, representationName(o.repr), o.deadzone,
                        s.context.deviceName());
  r.table += fmt::format("images: {} view{} ({}) at the last {} updates of each phase\n", s.views.size(),
                         s.views.size() == 1 ? "" : "s", o.scoredViews, o.scoredUpdates);
  r.table += fmt::format("{:<14} {:<7} {:>9} {:>9} {:>9} {:>9} {:>11} {:>11}\n", "rule", "stream", "still B",
                         "moving B", "again B", "flicker", "held flick", "PSNR loss");
}

// A rule's JSON; for the first seed also its table rows and its streams on the bytes chart (fixed
// rules as streamed today, the adaptive rule both ways).
nlohmann::json reportRule(const Setup& s, const RuleRun& run, bool firstSeed, std::string& table,
                          std::vector<imaging::ChartSeries>& bytesSeries) {
  const AdaptiveBenchOptions& o = s.o;
  nlohmann::json ruleJson = {{"rule", ruleName(run.rule)}, {"w_min", run.rule.wMin}, {"reject_sigmas", run.rule.rejectSigmas}};
  const auto flickerOver = [&](uint32_t end) {
    const std::vector<double> tail(run.changes.begin() + (end - o.stillUpdates / 2), run.changes.begin() + end);
    return session::median(tail);
  };
  ruleJson["flicker_rel"] = flickerOver(s.frames);
  ruleJson["restarted_probes_per_update"] = run.restarts;
  ruleJson["flicker_rel_first_still"] = flickerOver(o.stillUpdates);
  for (const Stream& st : run.streams) {
    const nlohmann::json sj = streamJson(s, run, st);
    ruleJson["streams"].push_back(sj);
    if (!firstSeed) continue;
    const size_t a = o.stillUpdates;
    table += fmt::format("{:<14} {:<7} {:>9.3f} {:>9.3f} {:>9.3f} {:>8.2f}% {:>10.2f}% {:>8.3f} dB\n", ruleName(run.rule),
                         st.name, mean(st.bytesPerProbe, a / 2, a), sj["moving_bytes_per_probe_frame"].get<double>(),
                         sj["static_bytes_per_probe_frame"].get<double>(), 100 * ruleJson["flicker_rel"].get<double>(),
                         100 * sj["held_flicker_rel_mean"].get<double>(), sj["worst_psnr_loss_db"].get<double>());
    if (st.name == "full") continue;
    const bool adaptiveNoise = run.rule.rejectSigmas > 0 && st.withNoise;
    if (!adaptiveNoise && st.withNoise) continue;
    imaging::ChartSeries series{ruleName(run.rule) + ", " + st.name + " stream", {}, true};
    for (uint32_t f = 1; f < s.frames; ++f) series.points.push_back({static_cast<double>(f), st.bytesPerProbe[f], ""});
    bytesSeries.push_back(std::move(series));
  }
  ruleJson["seed"] = run.seed;
  return ruleJson;
}

std::string bytesChart(const AdaptiveBenchOptions& o, const std::vector<imaging::ChartSeries>& bytesSeries) {
  imaging::ChartSpec spec;
  spec.title = fmt::format("Wire bytes per probe per frame: light still, moving (updates {}-{}), still", o.stillUpdates,
                           o.stillUpdates + o.movingUpdates);
  spec.xLabel = "update";
  spec.yLabel = "bytes per probe per frame";
  spec.footnote = o.command;
  return imaging::renderSvgChart(spec, bytesSeries);
}

// Every rule after a light jump on builtin:cornell 4³: the JSON, table lines and the error chart.
void addJump(renderer::VulkanContext& context, const AdaptiveBenchOptions& o, const std::vector<BlendRule>& rules,
             AdaptiveBenchResult& r) {
  sayProgress(o.progress, "adaptive bench: light jump");
  const std::vector<FlickerLag> jump = measureFlickerLag(context, rules, o.samplesPerProbe, o.jumpUpdates);
  const auto updates = [&](int n) { return n < 0 ? "> " + std::to_string(o.jumpUpdates) : std::to_string(n); };
  const auto errorSeries = [](const std::string& name, const std::vector<double>& error) {
    imaging::ChartSeries series{name, {}, true};
    for (size_t k = 0; k < error.size(); ++k) series.points.push_back({static_cast<double>(k + 1), error[k], ""});
    return series;
  };
  std::vector<imaging::ChartSeries> jumpSeries;
  r.table += "light jump (builtin:cornell 4x4x4, t 0 -> 0.5):\n";
  for (size_t i = 0; i < jump.size(); ++i) {
    const FlickerLag& f = jump[i];
    r.json["jump"].push_back({{"rule", ruleName(rules[i])},
                              {"flicker_rel", f.flickerRel},
                              {"error_before_jump", f.errorBeforeJump},
                              {"error_after_jump", f.errorAfterJump},
                              {"fresh_error", f.freshError},
                              {"follow_updates", f.updatesToFollow},
                              {"reconvergence_updates", f.updatesToRecover}});
    r.table += fmt::format("  {:<14} follows in {} updates, back to the pre-jump error in {} (flicker {:.2f}%)\n",
                           ruleName(rules[i]), updates(f.updatesToFollow), updates(f.updatesToRecover), 100 * f.flickerRel);
    jumpSeries.push_back(errorSeries(ruleName(rules[i]), f.errorAfterJump));
  }
  jumpSeries.push_back(errorSeries("fresh start on the new lighting", jump.back().freshError));
  imaging::ChartSpec spec;
  spec.title = "Irradiance error after the light jumps (builtin:cornell, 4x4x4)";
  spec.xLabel = "updates after the jump";
  spec.yLabel = "relative irradiance RMSE against the converged new lighting";
  spec.logY = true;
  spec.footnote = o.command;
  r.svgJump = imaging::renderSvgChart(spec, jumpSeries);
}

// The headline: the adaptive rule with the noise-aware stream.
void addSummary(nlohmann::json& j) {
  const nlohmann::json& adaptive = j["rules"].back();
  const nlohmann::json& noise = adaptive["streams"][2];
  j["summary"] = {{"static_bytes_per_probe_frame", noise["static_bytes_per_probe_frame"]},
                  {"moving_bytes_per_probe_frame", noise["moving_bytes_per_probe_frame"]},
                  {"flicker_rel", adaptive["flicker_rel"]},
                  {"follow_updates", j["jump"].back()["follow_updates"]},
                  {"reconvergence_updates", j["jump"].back()["reconvergence_updates"]},
                  {"worst_psnr_loss_db", noise["worst_psnr_loss_db"]}};
}

}  // namespace probecast::bench::adaptive
