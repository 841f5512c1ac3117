// Per-probe temporal statistics and the blending rule of the probe updater (probe_updater.h).
//
// Every update gives each probe a fresh estimate x (27 floats) and, from the spread of the
// estimate's independent partial sums, an estimate of its variance. Path-traced estimates have a
// heavy tail (a bright path now and then), so one disagreeing estimate only raises suspicion: it
// is held back, and the history restarts when the mean of it and the next estimate disagrees too
// and the next one, on its own, is off the history to the same side by more than k/2 standard
// errors. An outlier followed by a normal estimate is blended in as usual, keeping the mean
// unbiased: a mean of the two alone would restart on any outlier of about 1.5k or more, and did, on
// about one probe in 500 an update with the light still. The history keeps, for the
// luminance of c00 and of the three L1 coefficients, a Welford mean and sum of squares of the
// per-update estimates since its last restart; their variance σ² (pooled with the within-update
// estimate, which is all there is right after a restart) sets the standard error of the history,
// σ √f, where f = Var(history) / σ² follows the blend weights (f = 1/n for a true mean).
//
// An estimate may come from more or fewer samples than the nominal count per update (a ray
// budget, probe_updater.h): it then counts as `weight` = its samples / the nominal samples
// updates, its variance σ² / weight. Variances and weights are in units of one nominal update; a
// weight of exactly 1 gives the same floats as the rule without weights.
#pragma once

#include <cstdint>

namespace probecast::renderer {

constexpr int kHistoryLuma = 4;  // c00 and the L1 coefficients (sh.h order), as luminance

struct HistoryOptions {
  float minBlendWeight = 0.0f;  // w_min: w = max(1/n, w_min)
  float rejectSigmas = 0.0f;    // k: restart beyond k standard errors of the difference; 0 = never
};

struct ProbeHistory {
  float n = 0.0f;                   // estimates (nominal updates' worth) blended since the last restart
  float varianceFactor = 0.0f;      // f = Var(history) / σ²
  uint32_t welfordCount = 0;       // estimates in the statistics
  float welfordWeight = 0.0f;       // and their summed weight
  float mean[kHistoryLuma] = {};    // weighted Welford mean of the per-update luminance estimates
  float m2[kHistoryLuma] = {};      // and their weighted sum of squared deviations
  uint32_t spreadCount = 0;
  float spreadVariance[kHistoryLuma] = {};  // mean within-update variance estimate since the restart
  float fastCount = 0.0f;
  float fastFactor = 0.0f;          // Var(fast) / σ²
  float fast[27] = {};              // short moving average of the estimates
  bool pending = false;             // the last estimate disagreed: held back until the next one
  float pendingEstimate[27] = {};
  float pendingSpread[kHistoryLuma] = {};
  float pendingWeight = 0.0f;
};

// Accumulated: blended in. Held: it disagreed, the next estimate decides. Restarted: it and the
// held one agree with each other, not with the history. RestartedFromAverage: the short average
// drifted away from the history.
enum class BlendOutcome { Accumulated, Held, Restarted, RestartedFromAverage };

// Blends `estimate` into `probe` (27 floats) under the rule above; `spreadVariance` is this
// update's within-update variance estimate of the kHistoryLuma luminances (of this estimate, with
// its weight), `weight` > 0 the estimate's samples over the nominal samples per update.
BlendOutcome blendEstimate(ProbeHistory& history, float probe[27], const float estimate[27],
                           const float spreadVariance[kHistoryLuma], const HistoryOptions& options,
                           float weight = 1.0f);

// A neighbour restarted, so this probe's light has likely changed too: from now on its history
// counts for at most `n` estimates (its value, its variance and its statistics stay; new estimates
// weigh in as they would after n of them). A held-back estimate stays held.
void shortenHistory(ProbeHistory& history, float n);

// σ² of one update's estimate of luminance `k` (0 = c00), as the history knows it.
float estimateVariance(const ProbeHistory& history, int k);
// Standard error of the luminance of the history's c00 (ProbeVolume::noise).
float historyStandardError(const ProbeHistory& history);

float coefficientLuminance(const float probe[27], int coefficient);

}  // namespace probecast::renderer
