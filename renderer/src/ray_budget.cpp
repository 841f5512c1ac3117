// The ray budget's allocation (ray_budget.h).
#include "ray_budget.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <utility>
#include <vector>

namespace probecast::renderer {
namespace {

constexpr float kMaxRelativeVariance = 100.0f;  // a probe with (almost) no signal: noisy, not infinitely so
constexpr float kUntraced = 1e30f;              // the gain of a probe with no history: first in line

// How much the next lane's worth of samples lowers the probe's weighted variance, after `chunks`.
float gain(const ProbeNeed& need, uint32_t chunks, float delta, float outOfViewWeight) {
  const float view = std::max(std::clamp(need.viewWeight, 0.0f, 1.0f), outOfViewWeight);
  const float n = (need.suspect ? std::min(need.historyWeight, 1.0f) : need.historyWeight) + delta * static_cast<float>(chunks);
  if (!(n > 0.0f)) return kUntraced * view;
  const float s2 = std::isfinite(need.relativeVariance) ? std::clamp(need.relativeVariance, 0.0f, kMaxRelativeVariance)
                                                        : kMaxRelativeVariance;
  return view * s2 * (1.0f / n - 1.0f / (n + delta));
}

}  // namespace

uint64_t allocateRays(std::span<const ProbeNeed> needs, const RayBudgetRule& rule, uint32_t* samples) {
  const size_t count = needs.size();
  std::fill(samples, samples + count, 0u);
  if (count == 0 || rule.lane == 0) return 0;
  const uint32_t maxChunks = std::max(1u, rule.maxSamples / rule.lane);
  const uint64_t most = static_cast<uint64_t>(count) * maxChunks;
  const uint64_t total = std::min(std::max<uint64_t>(1, rule.rays / rule.lane), most);
  std::vector<uint32_t> chunks(count, 0);

  // The refresh share: one lane's worth each to the probes traced longest ago (ties: lower index).
  const double share = std::isfinite(rule.refreshShare) ? std::clamp<double>(rule.refreshShare, 0.0, 1.0) : 0.0;
  const uint64_t refresh = std::min<uint64_t>(count, static_cast<uint64_t>(std::ceil(share * static_cast<double>(total))));
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return needs[a].age > needs[b].age; });
  for (uint64_t i = 0; i < refresh; ++i) chunks[order[i]] = 1;

  // The rest by need, greedily.
  const float delta = static_cast<float>(rule.lane) / static_cast<float>(std::max(rule.nominalSamples, 1u));
  const float floorWeight = std::isfinite(rule.outOfViewWeight) ? std::clamp(rule.outOfViewWeight, 0.0f, 1.0f) : 0.0f;
  using Entry = std::pair<float, uint32_t>;  // gain, probe; ties: the lower probe first
  const auto lower = [](const Entry& a, const Entry& b) { return a.first < b.first || (a.first == b.first && a.second > b.second); };
  std::priority_queue<Entry, std::vector<Entry>, decltype(lower)> queue(lower);
  for (uint32_t p = 0; p < count; ++p)
    if (chunks[p] < maxChunks) queue.push({gain(needs[p], chunks[p], delta, floorWeight), p});
  for (uint64_t given = refresh; given < total && !queue.empty(); ++given) {
    const uint32_t p = queue.top().second;
    queue.pop();
    if (++chunks[p] < maxChunks) queue.push({gain(needs[p], chunks[p], delta, floorWeight), p});
  }
  uint64_t sum = 0;
  for (size_t p = 0; p < count; ++p) {
    samples[p] = chunks[p] * rule.lane;
    sum += samples[p];
  }
  return sum;
}

}  // namespace probecast::renderer
