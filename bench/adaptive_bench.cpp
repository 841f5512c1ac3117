#include "adaptive_bench.h"

#include <algorithm>

#include <fmt/format.h>

#include "adaptive_parts.h"

namespace probecast::bench {

using namespace adaptive;

namespace {

// The fixed rules, then the adaptive one; the adaptive rule again with each further seed (its
// figures per seed; the tables and charts are the first seed's).
std::vector<std::pair<uint32_t, BlendRule>> ruleRuns(const AdaptiveBenchOptions& o, const std::vector<BlendRule>& rules) {
  std::vector<std::pair<uint32_t, BlendRule>> runs;  // (seed, rule)
  for (uint32_t extra = 0; extra < std::max(o.streamSeeds, 1u); ++extra)
    for (const BlendRule& rule : rules)
      if (extra == 0 || rule.rejectSigmas > 0) runs.push_back({o.seed + extra, rule});
  return runs;
}

}  // namespace

AdaptiveBenchResult runAdaptiveBench(const AdaptiveBenchOptions& o) {
  renderer::VulkanContext context(o.context);
  AdaptiveBenchResult r;
  if (o.reconvergenceOnly) {
    r.json["command"] = o.command;
    r.json["device"] = context.deviceName();
    r.json["samples_per_probe"] = o.samplesPerProbe;
    r.json["seed"] = o.seed;
    addReconvergence(context, o, r);
    return r;
  }
  const Setup s(o, context);
  // Converged float volumes where images are scored: the end of each phase.
  Truth truth(s);
  for (const Moment& m : s.moments)
    for (uint32_t f = m.first; f <= m.frame; ++f) truth.converge(s.tAt(f), true);
  const Footprint footprint = o.viewWeights == "footprint" ? measureFootprint(s, truth) : Footprint{};
  // The oracle stream needs the truth at every update.
  if (!o.oracleErrorRatios.empty())
    for (uint32_t f = 0; f < s.frames; ++f) truth.converge(s.tAt(f), false);
  writeHeader(s, footprint, r);

  std::vector<BlendRule> rules;
  for (float w : o.fixedWMins) rules.push_back({w, 0.0f});
  rules.push_back({0.0f, o.rejectSigmas});
  std::vector<imaging::ChartSeries> bytesSeries;
  std::vector<nlohmann::json> adaptiveBySeed;
  for (const auto& [seed, rule] : ruleRuns(o, rules)) {
    const bool firstSeed = seed == o.seed;
    sayProgress(o.progress,
                fmt::format("adaptive bench: {}{}", ruleName(rule), firstSeed ? "" : fmt::format(", seed {}", seed)));
    const RuleRun run = runRule(s, truth, footprint.weights, seed, rule);
    if (!r.json.contains("active_probes")) r.json["active_probes"] = run.activeProbes;  // the same for every rule
    nlohmann::json ruleJson = reportRule(s, run, firstSeed, r.table, bytesSeries);
    if (rule.rejectSigmas > 0) adaptiveBySeed.push_back(ruleJson);
    if (firstSeed) r.json["rules"].push_back(std::move(ruleJson));
  }
  if (std::max(o.streamSeeds, 1u) > 1) addSeedSummary(adaptiveBySeed, o, r);
  r.svgBytes = bytesChart(o, bytesSeries);
  addJump(context, o, rules, r);
  addSummary(r.json);
  addReconvergence(context, o, r);
  return r;
}

}  // namespace probecast::bench
