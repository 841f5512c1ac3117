// SH basis, projection, irradiance and convention conversions against docs/CODEC.md §1 and §8.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "probecast/codec/sh.h"
#include "test_probes.h"

namespace probecast {
namespace {

using test::Probe;

// Projection ĉ = (4π/N) Σ L(ω) Y(ω) over a spherical Fibonacci set, summed in double.
Probe projectFunction(const std::function<void(const float d[3], float rgb[3])>& radiance, int count) {
  double acc[kProbeFloats] = {};
  const float golden = kPi * (3.0f - std::sqrt(5.0f));
  for (int i = 0; i < count; ++i) {
    const float z = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / static_cast<float>(count);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = golden * static_cast<float>(i);
    const float d[3] = {r * std::cos(phi), r * std::sin(phi), z};
    float rgb[3];
    radiance(d, rgb);
    float y[kShCoeffs];
    shEvalBasis(d[0], d[1], d[2], y);
    for (int k = 0; k < kShCoeffs; ++k)
      for (int c = 0; c < 3; ++c) acc[k * 3 + c] += static_cast<double>(y[k]) * rgb[c];
  }
  Probe p{};
  for (int k = 0; k < kProbeFloats; ++k) p[k] = static_cast<float>(acc[k] * 4.0 * M_PI / count);
  return p;
}

TEST(ShBasis, ConstantsMatchClosedForms) {
  // docs/CODEC.md §1: sqrt((2l+1)/(4π)) times the polynomial factors.
  EXPECT_NEAR(kY00, 0.5 / std::sqrt(M_PI), 1e-7);
  EXPECT_NEAR(kY1, std::sqrt(3.0 / (4.0 * M_PI)), 1e-7);
  EXPECT_NEAR(kY2, 0.5 * std::sqrt(15.0 / M_PI), 1e-7);
  EXPECT_NEAR(kY20, 0.25 * std::sqrt(5.0 / M_PI), 1e-7);
  EXPECT_NEAR(kY22, 0.25 * std::sqrt(15.0 / M_PI), 1e-7);
}

TEST(ShBasis, IndexOrderAndPolynomials) {
  float y[kShCoeffs];
  shEvalBasis(0.6f, 0.0f, 0.8f, y);  // x = 0.6, y = 0, z = 0.8
  EXPECT_FLOAT_EQ(y[1], 0.0f);               // Y1-1 ∝ y
  EXPECT_FLOAT_EQ(y[2], kY1 * 0.8f);         // Y10 ∝ z
  EXPECT_FLOAT_EQ(y[3], kY1 * 0.6f);         // Y11 ∝ x
  EXPECT_FLOAT_EQ(y[7], kY2 * 0.6f * 0.8f);  // Y21 ∝ xz
  EXPECT_FLOAT_EQ(y[8], kY22 * 0.36f);       // Y22 ∝ x² − y²
}

TEST(ShBasis, DeltaTowardOneTwoThreeMatchesKnownAnswer) {
  // docs/CODEC.md §8.3: coefficients of a unit delta are Y(d), d = normalize(1, 2, 3).
  const float inv = 1.0f / std::sqrt(14.0f);
  const float one[3] = {1, 1, 1};
  const Probe p = test::deltaProbe(1 * inv, 2 * inv, 3 * inv, one);
  const float expected[kShCoeffs] = {0.282095f, 0.261169f, 0.391754f, 0.130585f, 0.156078f,
                                     0.468235f, 0.292864f, 0.234118f, -0.117059f};
  for (int i = 0; i < kShCoeffs; ++i) EXPECT_NEAR(p[i * 3], expected[i], 1e-6f) << "coefficient " << i;
  const float l1 = std::sqrt(p[3] * p[3] + p[6] * p[6] + p[9] * p[9]);
  EXPECT_NEAR(l1 / p[0], std::sqrt(3.0f), 1e-5f);
}

TEST(ShBasis, ConstantRadianceProjectsToDcOnly) {
  // docs/CODEC.md §8.1: L = 1 → c00 = 2√π, all else 0; E = π everywhere.
  const Probe p = projectFunction([](const float*, float rgb[3]) { rgb[0] = rgb[1] = rgb[2] = 1.0f; }, 20000);
  EXPECT_NEAR(p[0], 3.5449077f, 1e-4f);
  for (int i = 1; i < kShCoeffs; ++i) EXPECT_NEAR(p[i * 3], 0.0f, 1e-3f) << i;
  std::mt19937 rng(1);
  for (int k = 0; k < 20; ++k) {
    float d[3], e[3];
    test::randomDirection(rng, d);
    shEvalIrradiance(p.data(), d[0], d[1], d[2], e);
    EXPECT_NEAR(e[0], kPi, 2e-3f);
  }
}

TEST(ShBasis, UpperHemisphereKnownAnswer) {
  // docs/CODEC.md §8.2: radiance 1 for z > 0 → c00 = √π, c10 = √(3π)/2, c20 = 0;
  // E(+z) = π, E(−z) = 0, E(equator) = π/2.
  const Probe p = projectFunction(
      [](const float d[3], float rgb[3]) { rgb[0] = rgb[1] = rgb[2] = d[2] > 0.0f ? 1.0f : 0.0f; }, 200000);
  EXPECT_NEAR(p[0], 1.7724539f, 1e-3f);
  EXPECT_NEAR(p[2 * 3], 1.5349900f, 1e-3f);
  EXPECT_NEAR(p[6 * 3], 0.0f, 1e-3f);
  float e[3];
  shEvalIrradiance(p.data(), 0, 0, 1, e);
  EXPECT_NEAR(e[0], kPi, 5e-3f);
  shEvalIrradiance(p.data(), 0, 0, -1, e);
  EXPECT_NEAR(e[0], 0.0f, 5e-3f);
  shEvalIrradiance(p.data(), 1, 0, 0, e);
  EXPECT_NEAR(e[0], kPi / 2, 5e-3f);
  // L1 alone is already exact here.
  shEvalIrradiance(p.data(), 0, 0, 1, e, 2);
  EXPECT_NEAR(e[0], kPi, 5e-3f);
}

TEST(ShBasis, IrradianceEqualsConvolvedRadiance) {
  std::mt19937 rng(7);
  Probe p = test::randomNonNegativeProbe(rng, 5, 0.1f);
  Probe conv = p;
  shConvolveCosine(conv.data());
  for (int k = 0; k < 10; ++k) {
    float d[3], e[3], r[3];
    test::randomDirection(rng, d);
    shEvalIrradiance(p.data(), d[0], d[1], d[2], e);
    shEvalRadiance(conv.data(), d[0], d[1], d[2], r);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], r[c], 1e-5f);
  }
}

TEST(ShBasis, CondonShortleyRoundTripAndSigns) {
  // CS basis: Y_1^1 = −√(3/4π) x, Y_2^1 = −√(15/4π) xz, so coefficients 3 and 7 flip sign (and 1, 5).
  const float rgb[3] = {1, 2, 3};
  const Probe p = test::deltaProbe(0.48f, 0.6f, 0.64f, rgb);
  Probe cs = p;
  shToggleCondonShortley(cs.data());
  EXPECT_FLOAT_EQ(cs[3 * 3], -kY1 * 0.48f);
  EXPECT_FLOAT_EQ(cs[7 * 3], -kY2 * 0.48f * 0.64f);
  for (int i : {0, 2, 4, 6, 8}) EXPECT_EQ(cs[i * 3 + 1], p[i * 3 + 1]);
  for (int i : {1, 3, 5, 7}) EXPECT_EQ(cs[i * 3 + 2], -p[i * 3 + 2]);
  shToggleCondonShortley(cs.data());
  EXPECT_EQ(cs, p);  // CS → no-CS → CS is the identity
}

TEST(ShBasis, BandEnergyIsRotationInvariant) {
  // docs/CODEC.md §8.6. Rotating every lobe of a sum of deltas rotates the function.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 10; ++trial) {
    // Random rotation from a random unit quaternion.
    float q[4];
    float len = 0;
    std::normal_distribution<float> n(0, 1);
    for (float& v : q) { v = n(rng); len += v * v; }
    len = std::sqrt(len);
    for (float& v : q) v /= len;
    const float w = q[0], x = q[1], y = q[2], z = q[3];
    const float rot[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                             {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                             {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    Probe a{}, b{};
    for (int k = 0; k < 4; ++k) {
      float d[3];
      test::randomDirection(rng, d);
      const float rgb[3] = {u(rng), u(rng), u(rng)};
      float r[3];
      for (int i = 0; i < 3; ++i) r[i] = rot[i][0] * d[0] + rot[i][1] * d[1] + rot[i][2] * d[2];
      shAddSample(a.data(), d[0], d[1], d[2], rgb, 1.0f);
      shAddSample(b.data(), r[0], r[1], r[2], rgb, 1.0f);
    }
    for (int band = 0; band < 3; ++band)
      EXPECT_NEAR(shBandEnergy(a.data(), band), shBandEnergy(b.data(), band), 1e-4f * (1 + shBandEnergy(a.data(), band)));
  }
}

}  // namespace
}  // namespace probecast
