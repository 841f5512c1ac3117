// GGX zonal-harmonic lobe scales and the environment BRDF table.
#include <gtest/gtest.h>

#include <cmath>

#include "probecast/renderer/glossy_sh.h"

namespace probecast::renderer {
namespace {

TEST(GlossySh, LobeScalesLimits) {
  // A nearly mirror lobe keeps every band (g_l → 1); the roughest lobe is a cos-weighted GGX of
  // α = 1, i.e. K ∝ cos θ on the hemisphere (D is constant for α = 1): g_1 = 2/3, g_2 = 1/4,
  // the clamped-cosine ratios Â_l / Â_0 of docs/CODEC.md §1.
  const auto sharp = ggxLobeScalesIntegrated(0.05);
  EXPECT_GT(sharp[1], 0.99);
  EXPECT_GT(sharp[2], 0.98);
  const auto rough = ggxLobeScalesIntegrated(1.0);
  EXPECT_NEAR(rough[1], 2.0 / 3.0, 1e-4);
  EXPECT_NEAR(rough[2], 0.25, 1e-4);
}

TEST(GlossySh, FitMatchesDirectIntegration) {
  // The closed-form fit against the numerical convolution at roughnesses it was not fitted on
  // (measured worst absolute error 0.0068, at band 2).
  const GgxLobeFit fit = ggxLobeFit();
  double worst = 0;
  for (double r = 0.0125; r < 1.0; r += 0.05) {
    const auto truth = ggxLobeScalesIntegrated(r);
    const auto approx = fit.evaluate(r);
    for (int l = 1; l < 3; ++l) worst = std::max(worst, std::fabs(truth[l] - approx[l]));
  }
  EXPECT_LT(worst, 0.01) << "worst " << worst << " band2 " << fit.band2[0] << " " << fit.band2[1] << " " << fit.band2[2] << " "
                         << fit.band2[3];
  // Monotone: rougher lobes blur more.
  EXPECT_GT(fit.evaluate(0.3)[2], fit.evaluate(0.6)[2]);
}

TEST(GlossySh, EnvBrdfKnownValues) {
  // Smooth limit (r → 0, G → 1): A = 1 − (1 − n·v)^5, B = (1 − n·v)^5 (Schlick's Fresnel split).
  const int size = 32;
  const std::vector<float> t = envBrdfTable(size, 256);
  const int vi = 15;  // n·v = 15.5/32
  const double nv = 15.5 / 32, fc = std::pow(1 - nv, 5);
  EXPECT_NEAR(t[(0 * size + vi) * 2], 1 - fc, 0.02);
  EXPECT_NEAR(t[(0 * size + vi) * 2 + 1], fc, 0.01);
  // Energy never exceeds one and roughness loses some at grazing angles.
  for (size_t i = 0; i < t.size(); i += 2) {
    EXPECT_GE(t[i], 0.0f);
    EXPECT_GE(t[i + 1], 0.0f);
    EXPECT_LE(t[i] + t[i + 1], 1.0f + 1e-3f);
  }
  EXPECT_LT(t[((size - 1) * size + 0) * 2] + t[((size - 1) * size + 0) * 2 + 1], 0.9f);
}

}  // namespace
}  // namespace probecast::renderer
