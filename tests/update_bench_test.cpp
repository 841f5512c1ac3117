// bench update on a tiny grid: the fields it promises, convergence, and memory that does not grow
// with samples.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "update_bench.h"

namespace probecast::bench {
namespace {

TEST(UpdateBench, ReportsConvergingErrorAndRays) {
  UpdateBenchOptions o;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, o.scene, error));
  o.grid = ProbeGrid{{3, 2, 3}, {{-0.7f, 0.8f, -0.7f}, {0.7f, 1.8f, 0.7f}}};
  o.updater.samplesPerProbe = 128;
  o.updates = 6;
  o.referenceSamples = 4096;
  o.minBlendWeights = {0.25f};
  o.context.validation = true;
  const UpdateBenchResult r = runUpdateBench(o);
  const auto& j = r.json;
  EXPECT_GT(j["rays_per_s"].get<double>(), 0.0);
  EXPECT_GT(j["closest_hit_rays_per_s"].get<double>(), 0.0);
  EXPECT_GT(j["shadow_rays_per_s"].get<double>(), 0.0);
  EXPECT_GT(j["ms_per_update"].get<double>(), 0.0);
  const auto errors = j["rmse_rel_after_updates"].get<std::vector<double>>();
  ASSERT_EQ(errors.size(), 6u);
  EXPECT_LT(errors.back(), errors.front());  // accumulating more samples approaches the reference
  ASSERT_EQ(j["flicker_rel"].size(), 1u);
  EXPECT_GT(j["flicker_rel"][0]["flicker_rel"].get<double>(), 0.0);
  EXPECT_NE(r.svg.find("<svg"), std::string::npos);
}

TEST(UpdateBench, DeviceMemoryDoesNotGrowWithSamples) {
  // Per-lane partial sums instead of a per-sample buffer: going from 64 to 2048 samples per probe
  // adds only the direction table (16 bytes a sample).
  renderer::VulkanContext context;
  scene::Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, s, error));
  ProbeGrid g;
  g = ProbeGrid{{8, 8, 8}, {{-0.8f, 0.2f, -0.8f}, {0.8f, 1.8f, 0.8f}}};
  renderer::UpdaterOptions a, b;
  a.samplesPerProbe = 64;
  b.samplesPerProbe = 2048;
  renderer::ProbeUpdater ua(context, s, g, a), ub(context, s, g, b);
  EXPECT_EQ(ub.deviceBytes() - ua.deviceBytes(), (2048u - 64u) * 16u);
}

TEST(UpdateBench, PerProbeErrorCountsADimProbeAsMuchAsABrightOne) {
  // Four probes, DC only (the bands' weights cancel in every ratio): a bright one 10 % off, a dim
  // one 50 % off, an inactive one far off and a black one. Pooled, the bright probe's energy hides
  // the dim one's error: sqrt((1 + 0.25) / (100 + 1)) = 0.111. Per probe: sqrt((0.1² + 0.5²) / 2) =
  // 0.361; the inactive and the black probe are left out (counting the black one would give 0.294).
  std::vector<float> test(4 * kProbeFloats, 0.0f), reference(4 * kProbeFloats, 0.0f);
  const float dc[4][2] = {{11.0f, 10.0f}, {1.5f, 1.0f}, {50.0f, 1.0f}, {0.0f, 0.0f}};  // {test, reference}
  for (int p = 0; p < 4; ++p)
    for (int c = 0; c < 3; ++c) {
      test[p * kProbeFloats + c] = dc[p][0];
      reference[p * kProbeFloats + c] = dc[p][1];
    }
  const uint8_t active[4] = {1, 1, 0, 1};
  EXPECT_NEAR(irradianceRmseRel(test.data(), reference.data(), active, 4), std::sqrt(1.25 / 101.0), 1e-6);
  EXPECT_NEAR(irradianceRmseRelPerProbe(test.data(), reference.data(), active, 4), std::sqrt(0.13), 1e-6);
  EXPECT_EQ(irradianceRmseRelPerProbe(test.data(), test.data(), nullptr, 4), 0.0);
}

}  // namespace
}  // namespace probecast::bench
