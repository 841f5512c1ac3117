// History rejection and the running noise estimate of each probe (probe_history.h).
#include "probe_history.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>

namespace probecast::renderer {
namespace {

constexpr float kFastWeight = 0.25f;  // the short moving average: ≈ the last 7 estimates
// The within-update estimate counts as this many degrees of freedom next to the Welford sum of
// squares (m − 1 of them after m estimates): it decides right after a restart, then fades.
constexpr float kSpreadDegrees = 4.0f;
// A change of this fraction of the history's luminance is never called noise-free: it keeps a
// probe with a (near) deterministic estimate from restarting on rounding.
constexpr float kRelativeFloor = 1e-3f;

void addStatistics(ProbeHistory& h, const float estimate[27], const float spread[kHistoryLuma], float weight) {
  // West's weighted form of Welford's update: an estimate of variance σ² / weight counts `weight`
  // times, so m2 / (count − 1) still estimates σ² (the spread is of this estimate: σ² / weight).
  ++h.welfordCount;
  h.welfordWeight += weight;
  ++h.spreadCount;
  for (int k = 0; k < kHistoryLuma; ++k) {
    const float x = coefficientLuminance(estimate, k);
    const float delta = x - h.mean[k];
    h.mean[k] += delta * weight / h.welfordWeight;
    h.m2[k] += weight * delta * (x - h.mean[k]);
    h.spreadVariance[k] += (spread[k] * weight - h.spreadVariance[k]) / static_cast<float>(h.spreadCount);
  }
}

// The blend weight of `weight` updates' worth under a floor of `floor` per update: what that
// many successive updates at the floor would give.
float floorFor(float floor, float weight) {
  return weight == 1.0f ? floor : 1.0f - std::pow(1.0f - floor, weight);
}

struct Estimate {
  const float* value;
  const float* spread;
  float weight;
};

// The history becomes `probe`, worth `n` estimates; the statistics restart from `estimates`.
void restart(ProbeHistory& h, float probe[27], const float value[27], float n, std::initializer_list<Estimate> estimates) {
  std::copy(value, value + 27, probe);
  std::copy(value, value + 27, h.fast);
  h.n = n;
  h.varianceFactor = 1.0f / n;
  h.fastCount = n;
  h.fastFactor = h.varianceFactor;
  h.welfordCount = 0;
  h.welfordWeight = 0.0f;
  h.spreadCount = 0;
  std::fill(h.mean, h.mean + kHistoryLuma, 0.0f);
  std::fill(h.m2, h.m2 + kHistoryLuma, 0.0f);
  std::fill(h.spreadVariance, h.spreadVariance + kHistoryLuma, 0.0f);
  for (const Estimate& e : estimates) addStatistics(h, e.value, e.spread, e.weight);
  h.pending = false;
}

// Blends one estimate into the history; `fastInput` is what the short average gets (the history
// itself for an estimate that disagreed on its own, so one outlier cannot move it far).
void accumulate(ProbeHistory& h, float probe[27], const Estimate& e, const float fastInput[27], float minBlendWeight) {
  h.n += e.weight;
  const float w = std::min(1.0f, std::max(e.weight / h.n, floorFor(minBlendWeight, e.weight)));
  for (int i = 0; i < 27; ++i) probe[i] = (1.0f - w) * probe[i] + w * e.value[i];
  h.varianceFactor = (1.0f - w) * (1.0f - w) * h.varianceFactor + w * w / e.weight;
  addStatistics(h, e.value, e.spread, e.weight);
  h.fastCount += e.weight;
  const float wf = std::min(1.0f, std::max(e.weight / h.fastCount, floorFor(kFastWeight, e.weight)));
  for (int i = 0; i < 27; ++i) h.fast[i] = (1.0f - wf) * h.fast[i] + wf * fastInput[i];
  h.fastFactor = (1.0f - wf) * (1.0f - wf) * h.fastFactor + wf * wf / e.weight;
}

// True when `a` and `b` differ by more than k standard errors in any of the luminances, the
// difference having variance σ² · factor.
bool disagree(const ProbeHistory& h, const float a[27], const float b[27], float factor, float k) {
  for (int c = 0; c < kHistoryLuma; ++c) {
    const float d = coefficientLuminance(a, c) - coefficientLuminance(b, c);
    const float floor = kRelativeFloor * std::fabs(coefficientLuminance(b, 0));
    const float variance = estimateVariance(h, c) * factor + floor * floor;
    if (d * d > k * k * variance) return true;
  }
  return false;
}

// True when `next` departs from `history` the way `held` did: in some luminance, `next` is off the
// history to the same side as `held` and by more than k standard errors, the difference having
// variance σ² · factor. A bright path now and then is not followed by another.
bool confirms(const ProbeHistory& h, const float held[27], const float next[27], const float history[27], float factor,
              float k) {
  for (int c = 0; c < kHistoryLuma; ++c) {
    const float base = coefficientLuminance(history, c);
    const float a = coefficientLuminance(held, c) - base, b = coefficientLuminance(next, c) - base;
    const float floor = kRelativeFloor * std::fabs(coefficientLuminance(history, 0));
    const float variance = estimateVariance(h, c) * factor + floor * floor;
    if (a * b > 0.0f && b * b > k * k * variance) return true;
  }
  return false;
}

}  // namespace

float coefficientLuminance(const float probe[27], int coefficient) {
  const float* c = probe + coefficient * 3;
  return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

float estimateVariance(const ProbeHistory& h, int k) {
  const float dof = h.welfordCount > 1 ? static_cast<float>(h.welfordCount - 1) : 0.0f;
  return (h.m2[k] + kSpreadDegrees * h.spreadVariance[k]) / (dof + kSpreadDegrees);
}

void shortenHistory(ProbeHistory& h, float n) {
  if (!(n > 0.0f) || h.n <= n) return;
  // Only the weights to come change: the value, hence its variance, is what it was.
  h.n = n;
  h.fastCount = std::min(h.fastCount, n);
}

float historyStandardError(const ProbeHistory& h) {
  return h.n == 0.0f ? 0.0f : std::sqrt(std::max(0.0f, estimateVariance(h, 0) * h.varianceFactor));
}

BlendOutcome blendEstimate(ProbeHistory& h, float probe[27], const float estimate[27],
                           const float spread[kHistoryLuma], const HistoryOptions& o, float weight) {
  const Estimate fresh{estimate, spread, weight};
  if (h.n == 0.0f) {
    restart(h, probe, estimate, weight, {fresh});
    return BlendOutcome::Accumulated;
  }
  if (!(o.rejectSigmas > 0.0f)) {
    accumulate(h, probe, fresh, estimate, o.minBlendWeight);
    return BlendOutcome::Accumulated;
  }
  const float k = o.rejectSigmas;
  // A new estimate and the history differ by noise of variance σ² (1 / weight + f) when nothing moved.
  const bool alone = disagree(h, estimate, probe, 1.0f / weight + h.varianceFactor, k);
  if (h.pending) {
    const Estimate held{h.pendingEstimate, h.pendingSpread, h.pendingWeight};
    const float both = held.weight + weight;
    float pair[27];  // their weighted mean, of variance σ² / both
    for (int i = 0; i < 27; ++i) pair[i] = (held.weight * held.value[i] + weight * estimate[i]) / both;
    if (disagree(h, pair, probe, 1.0f / both + h.varianceFactor, k) &&
        confirms(h, held.value, estimate, probe, 1.0f / weight + h.varianceFactor, 0.5f * k)) {
      restart(h, probe, pair, both, {held, fresh});
      return BlendOutcome::Restarted;
    }
    h.pending = false;
    accumulate(h, probe, held, probe, o.minBlendWeight);
  } else if (alone) {
    std::copy(estimate, estimate + 27, h.pendingEstimate);
    std::copy(spread, spread + kHistoryLuma, h.pendingSpread);
    h.pendingWeight = weight;
    h.pending = true;
    return BlendOutcome::Held;
  }
  accumulate(h, probe, fresh, alone ? probe : estimate, o.minBlendWeight);
  // A change below one update's noise shows in the short average within a few updates. Their
  // difference has variance at most σ² (f_fast + f) (the two share samples, which only lowers it).
  if (disagree(h, h.fast, probe, h.fastFactor + h.varianceFactor, k)) {
    float fast[27];
    std::copy(h.fast, h.fast + 27, fast);
    const float n = static_cast<float>(std::max(1L, std::lround(1.0f / h.fastFactor)));
    restart(h, probe, fast, n, {fresh});
    return BlendOutcome::RestartedFromAverage;
  }
  return BlendOutcome::Accumulated;
}

}  // namespace probecast::renderer
