// The per-update ray budget of the probe updater (UpdaterOptions::raysPerUpdate): probes in view
// get more samples, every probe gets some, a probe left without rays keeps its history, and no
// budget is the plain update bit for bit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "probe_history.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/renderer/probe_interest.h"
#include "probecast/renderer/probe_updater.h"
#include "vulkan_test_support.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {
namespace {

// Every test checks the validation layer stayed silent.
class RayBudget : public ::testing::Test {
 protected:
  void TearDown() override { EXPECT_EQ(context_.validationMessages(), 0u) << "Vulkan validation messages"; }
  VulkanContext context_{test::validatedContext()};
};

scene::Scene cornell(float t) { return test::builtinScene("cornell", t); }

// FNV-1a over the bytes of the floats.
uint64_t fnv(const std::vector<float>& v) {
  uint64_t h = 1469598103934665603ull;
  for (float f : v) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    for (int b = 0; b < 4; ++b) h = (h ^ ((bits >> (8 * b)) & 0xffu)) * 1099511628211ull;
  }
  return h;
}

TEST_F(RayBudget, NoBudgetIsThePlainUpdateBitForBit) {
  // Pinned from the updater before it had a budget: 3³ probes of builtin:cornell, 64 spp, 4
  // updates with the light moved after the second (a restart), default blending.
  UpdaterOptions o;
  o.samplesPerProbe = 64;
  ProbeUpdater u(context_, cornell(0.0f), sceneGrid(cornell(0.0f), {3, 3, 3}), o);
  u.update();
  u.update();
  u.setScene(cornell(0.5f));
  u.update();
  u.update();
  EXPECT_EQ(fnv(u.volume().probes), 0xe1e00875c72e841bull);
  EXPECT_EQ(fnv(u.volume().noise), 0x18eba08be0017cb4ull);
  for (uint32_t n : u.lastSamples()) EXPECT_EQ(n, 64u);
}

TEST_F(RayBudget, ABudgetOfSppForEveryProbeIsThePlainUpdate) {
  // Every probe at its cap of samplesPerProbe, the cap times the probes: the per-probe path of the
  // tracer (own direction sets, own counts) and the blend weight of 1 give the same floats.
  UpdaterOptions plain;
  plain.samplesPerProbe = 64;
  UpdaterOptions budget = plain;
  budget.raysPerUpdate = 27 * 64;
  budget.maxSamplesPerProbe = 64;
  const scene::Scene s = cornell(0.0f);
  ProbeUpdater a(context_, s, sceneGrid(s, {3, 3, 3}), plain), b(context_, s, sceneGrid(s, {3, 3, 3}), budget);
  for (int k = 0; k < 3; ++k) {
    a.update();
    EXPECT_EQ(b.update().paths, 27u * 64u);
  }
  EXPECT_EQ(a.volume().probes, b.volume().probes);
  EXPECT_EQ(a.volume().noise, b.volume().noise);
}

// Orthographic view down −z over x in [cx − h, cx + h], y in [cy − h, cy + h], from z = eyeZ.
View orthoView(float cx, float cy, float eyeZ, float h, float far) {
  View v{};
  v.viewProj[0] = 1.0f / h;
  v.viewProj[5] = 1.0f / h;
  v.viewProj[10] = -1.0f / far;
  v.viewProj[12] = -cx / h;
  v.viewProj[13] = -cy / h;
  v.viewProj[14] = eyeZ / far;
  v.viewProj[15] = 1.0f;
  v.eye[0] = cx, v.eye[1] = cy, v.eye[2] = eyeZ;
  return v;
}

// The view of the lower two of four probe columns along x (their trilinear support, one cell
// either side, and no more of the next column's).
View halfView(const ProbeGrid& g) {
  const float cell = probeCellSize(g, 0);
  const float cy = 0.5f * (g.bounds.min[1] + g.bounds.max[1]);
  return orthoView(g.bounds.min[0] - 0.25f * cell, cy, g.bounds.max[2] + 10.0f, 0.75f * cell, 100.0f);
}

TEST_F(RayBudget, InViewProbesGetMoreAndEveryProbeSomeWithinTenUpdates) {
  const scene::Scene s = cornell(0.0f);
  const ProbeGrid g = sceneGrid(s, {4, 4, 4});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.raysPerUpdate = 64 * 32;  // what brute force spends
  ProbeUpdater u(context_, s, g, o);
  const View view = halfView(g);
  const std::vector<float> weights = probeViewWeights(g, u.volume().offsets, std::span<const View>(&view, 1));
  uint32_t seen = 0;
  for (float w : weights) seen += w > 0.0f ? 1u : 0u;
  ASSERT_EQ(seen, 32u) << "the view covers half the volume";
  u.setViewWeights(weights);
  std::vector<uint64_t> total(g.count(), 0);
  // The refresh share traces ceil(10 % of 64 lanes) = 7 probes each update, the longest untraced
  // first: all 64 within 10 updates, whatever else the budget does.
  for (int k = 0; k < 10; ++k) {
    const UpdateStats st = u.update();
    EXPECT_EQ(st.paths, 64u * 32u);
    for (uint32_t p = 0; p < g.count(); ++p) {
      EXPECT_EQ(u.lastSamples()[p] % 32u, 0u);
      EXPECT_LE(u.lastSamples()[p], 8u * 32u);
      total[p] += u.lastSamples()[p];
    }
  }
  for (uint32_t p = 0; p < g.count(); ++p)
    if (u.volume().active[p]) {
      EXPECT_GT(total[p], 0u) << "probe " << p << " never traced";
    }
  for (int k = 0; k < 10; ++k) {
    u.update();
    for (uint32_t p = 0; p < g.count(); ++p) total[p] += u.lastSamples()[p];
  }
  double in = 0, out = 0;
  for (uint32_t p = 0; p < g.count(); ++p) (weights[p] > 0 ? in : out) += static_cast<double>(total[p]);
  EXPECT_GT(in, 2.0 * out) << "in view " << in << ", out of view " << out << " samples over 20 updates";
}

TEST_F(RayBudget, AProbeGivenNoRaysKeepsItsValueAndItsNoise) {
  const scene::Scene s = cornell(0.0f);
  const ProbeGrid g = sceneGrid(s, {4, 4, 4});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.raysPerUpdate = 16 * 32;  // a quarter of the probes' worth: most get nothing each update
  ProbeUpdater u(context_, s, g, o);
  const View view = halfView(g);
  u.setViewWeights(probeViewWeights(g, u.volume().offsets, std::span<const View>(&view, 1)));
  uint32_t kept = 0, changed = 0;
  for (int k = 0; k < 12; ++k) {
    const std::vector<float> probes = u.volume().probes, noise = u.volume().noise;
    u.update();
    if (noise.empty()) continue;
    for (uint32_t p = 0; p < g.count(); ++p) {
      const bool same = std::equal(probes.begin() + p * 27, probes.begin() + (p + 1) * 27, u.volume().probes.begin() + p * 27) &&
                        noise[p] == u.volume().noise[p];
      if (u.lastSamples()[p] == 0) {
        EXPECT_TRUE(same) << "probe " << p << " got no rays in update " << k;
        kept += noise[p] > 0.0f ? 1u : 0u;  // one with a history to keep
      } else {
        changed += same ? 0u : 1u;
      }
    }
  }
  EXPECT_GT(kept, 100u);
  EXPECT_GT(changed, 100u);
}

TEST_F(RayBudget, AnAbsurdBudgetIsCappedAndBadViewWeightsAreRefused) {
  const scene::Scene s = cornell(0.0f);
  const ProbeGrid g = sceneGrid(s, {3, 3, 3});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.raysPerUpdate = std::numeric_limits<uint64_t>::max();
  ProbeUpdater u(context_, s, g, o);
  const UpdateStats st = u.update();
  EXPECT_EQ(st.paths, static_cast<uint64_t>(st.activeProbes) * 8u * 32u);  // every probe at its cap
  EXPECT_THROW(u.setViewWeights(std::vector<float>(g.count(), std::nanf(""))), std::invalid_argument);
  EXPECT_THROW(u.setViewWeights(std::vector<float>(g.count(), 2.0f)), std::invalid_argument);
  EXPECT_THROW(u.setViewWeights(std::vector<float>(g.count() + 1, 1.0f)), std::invalid_argument);
  View bad = halfView(g);
  bad.viewProj[0] = std::numeric_limits<float>::infinity();
  const std::vector<float> none = probeViewWeights(g, {}, std::span<const View>(&bad, 1));
  ASSERT_EQ(none.size(), g.count());
  for (float w : none) EXPECT_EQ(w, 0.0f);  // a view of nonsense sees nothing
  u.setViewWeights(none);
  EXPECT_EQ(u.update().paths, static_cast<uint64_t>(st.activeProbes) * 8u * 32u);
}

// A probe (or estimate) with every coefficient `v`, and the spread and plain rule the blend tests use.
std::array<float, 27> filled(float v) {
  std::array<float, 27> a;
  a.fill(v);
  return a;
}
constexpr float kSpread[kHistoryLuma] = {0.04f, 0.04f, 0.04f, 0.04f};  // σ = 0.2 per estimate
constexpr HistoryOptions kPlain{0.0f, 0.0f};                             // no floor, no rejection

TEST(RayBudgetBlend, AnEstimateCountsAsItsSamplesOverTheNominal) {
  // A plain mean (no floor, no rejection): one estimate of weight 1, then one of weight 3, is the
  // history (a + 3b) / 4 worth 4 updates, of variance σ²/4.
  ProbeHistory h;
  float probe[27] = {};
  blendEstimate(h, probe, filled(1.0f).data(), kSpread, kPlain, 1.0f);
  blendEstimate(h, probe, filled(2.0f).data(), kSpread, kPlain, 3.0f);
  EXPECT_FLOAT_EQ(probe[0], 1.75f);
  EXPECT_FLOAT_EQ(h.n, 4.0f);
  EXPECT_FLOAT_EQ(h.varianceFactor, 0.25f);
}

TEST(NeighbourHistory, AShortenedHistoryWeighsTheNextEstimateAsAfterNOfThem) {
  // A plain mean of 100 estimates of 1, shortened to 8: an estimate of 10 then moves it by 1/9 of
  // the way (w = 1/(8+1)); the shortening itself leaves the value and its variance as they were
  // (only the weights to come change). One already shorter than the cap, and a cap of 0, leave it
  // as it is.
  ProbeHistory h;
  float probe[27] = {};
  for (int k = 0; k < 100; ++k) blendEstimate(h, probe, filled(1.0f).data(), kSpread, kPlain, 1.0f);
  EXPECT_FLOAT_EQ(h.varianceFactor, 0.01f);
  ProbeHistory same = h;
  shortenHistory(same, 0.0f);
  EXPECT_FLOAT_EQ(same.n, 100.0f);
  shortenHistory(h, 8.0f);
  EXPECT_FLOAT_EQ(h.n, 8.0f);
  EXPECT_FLOAT_EQ(h.varianceFactor, 0.01f);
  EXPECT_FLOAT_EQ(probe[0], 1.0f);  // its value stays
  blendEstimate(h, probe, filled(10.0f).data(), kSpread, kPlain, 1.0f);
  EXPECT_FLOAT_EQ(probe[0], 2.0f);  // 1 + (10 - 1) / 9
  EXPECT_FLOAT_EQ(h.varianceFactor, 0.01f * 64.0f / 81.0f + 1.0f / 81.0f);  // (1 - w)² f + w²
  shortenHistory(h, 20.0f);
  EXPECT_FLOAT_EQ(h.n, 9.0f);
}

TEST(HistoryRejection, ABrightEstimateFollowedByANormalOneIsBlendedInTwoThatAgreeRestart) {
  // A history of 50 estimates alternating 0.9 and 1.1 in every coefficient (σ = 0.1, the spread
  // saying the same), k = 4. One estimate 12σ bright (2.2) is held back; the next is normal (1.0):
  // their mean (1.6) is 6σ off, but the normal one does not lean its way, so both are blended in
  // (the history, worth 52 estimates, is their plain mean) and nothing restarts. Two estimates
  // 6σ off (1.6, 1.6) are a jump: held, then restarted from their mean, worth 2.
  const float spread[kHistoryLuma] = {0.01f, 0.01f, 0.01f, 0.01f};
  const HistoryOptions rule{0.0f, 4.0f};
  struct After {
    BlendOutcome first, second;
    float n, value;
  };
  // Two estimates, `a` then `b`, into a converged history of 1.
  const auto after = [&](float a, float b) {
    ProbeHistory h;
    float probe[27] = {};
    for (int k = 0; k < 50; ++k) blendEstimate(h, probe, filled(k % 2 ? 1.1f : 0.9f).data(), spread, rule);
    EXPECT_NEAR(probe[0], 1.0f, 1e-5f);
    EXPECT_FLOAT_EQ(h.n, 50.0f);
    After r{};
    r.first = blendEstimate(h, probe, filled(a).data(), spread, rule);
    r.second = blendEstimate(h, probe, filled(b).data(), spread, rule);
    r.n = h.n;
    r.value = probe[0];
    return r;
  };
  const After outlier = after(2.2f, 1.0f);
  EXPECT_EQ(outlier.first, BlendOutcome::Held);
  EXPECT_EQ(outlier.second, BlendOutcome::Accumulated);
  EXPECT_FLOAT_EQ(outlier.n, 52.0f);
  EXPECT_NEAR(outlier.value, (50.0f + 2.2f + 1.0f) / 52.0f, 1e-5f);  // the plain mean of all 52
  const After jump = after(1.6f, 1.6f);
  EXPECT_EQ(jump.first, BlendOutcome::Held);
  EXPECT_EQ(jump.second, BlendOutcome::Restarted);
  EXPECT_FLOAT_EQ(jump.n, 2.0f);
  EXPECT_FLOAT_EQ(jump.value, 1.6f);
}

}  // namespace
}  // namespace probecast::renderer
