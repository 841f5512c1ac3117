// ZH3 axis, stored and hallucinated zonal coefficients (docs/CODEC.md §2, §8.3-8.4).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "probecast/codec/record.h"
#include "probecast/codec/zh3.h"
#include "test_probes.h"

namespace probecast {
namespace {

using test::Probe;

TEST(Zh3, HallucinationMatchesCurve) {
  // docs/CODEC.md §8.4: c20'/c00 = 0.08 r + 0.6 r².
  EXPECT_NEAR(zh3HallucinationCurve(0.5f), 0.19f, 1e-6f);
  EXPECT_NEAR(zh3HallucinationCurve(1.0f), 0.68f, 1e-6f);
  EXPECT_NEAR(zh3HallucinationCurve(1.5f), 1.47f, 1e-6f);
  EXPECT_NEAR(zh3HallucinationCurve(std::sqrt(3.0f)), 1.938564f, 1e-5f);
}

TEST(Zh3, DeltaAxisAndStoredCoefficient) {
  // docs/CODEC.md §8.3: on its own axis a delta has c20'/c00 = √5 and z = 1.
  const float inv = 1.0f / std::sqrt(14.0f);
  const float d[3] = {1 * inv, 2 * inv, 3 * inv};
  const float one[3] = {1, 1, 1};
  const Probe p = test::deltaProbe(d[0], d[1], d[2], one);
  float axis[3];
  zh3Axis(p.data(), axis);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(axis[k], d[k], 1e-6f);
  float zonal[3];
  zh3Project(p.data(), axis, zonal);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(zonal[c], 1.0f, 1e-5f);
  const float c20 = zonal[0] / std::sqrt(4.0f * kPi / 5.0f);
  EXPECT_NEAR(c20 / p[0], std::sqrt(5.0f), 1e-5f);
}

TEST(Zh3, ExpansionReproducesZonalFunctions) {
  // A delta is zonal around its direction, so L1 + stored ZH3 holds all of its L2 band.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    float d[3];
    test::randomDirection(rng, d);
    const float rgb[3] = {1.0f, 0.5f, 0.25f};
    const Probe p = test::deltaProbe(d[0], d[1], d[2], rgb);
    float axis[3], zonal[3];
    zh3Axis(p.data(), axis);
    zh3Project(p.data(), axis, zonal);
    Probe q = p;
    zh3ExpandToL2(q.data(), axis, zonal);
    for (int i = 0; i < kProbeFloats; ++i) EXPECT_NEAR(q[i], p[i], 1e-5f);
  }
}

TEST(Zh3, HallucinationUnderestimatesDeltaButKeepsAxis) {
  // For a delta r = √3: hallucinated c20'/c00 = 1.938564 against the true √5 (docs/CODEC.md §8.4).
  const float one[3] = {1, 1, 1};
  Probe p = test::deltaProbe(0, 0, 1, one);
  zh3HallucinateInPlace(p.data());
  const float c20 = p[6 * 3];
  // Around +z, Y20 is the only L2 term: c20 = c00 · 1.938564.
  EXPECT_NEAR(c20 / p[0], 1.938564f, 1e-4f);
  for (int i : {4, 5, 7, 8}) EXPECT_NEAR(p[i * 3], 0.0f, 1e-6f);
}

TEST(Zh3, HallucinationAddsNothingWithoutDirectionality) {
  // docs/CODEC.md §8.6: r = 0 → no L2. A constant probe has no L1 at all.
  Probe p{};
  for (int c = 0; c < 3; ++c) p[c] = 2.0f;
  p[12] = 0.3f;  // some L2 that the hallucination must replace with zeros
  zh3HallucinateInPlace(p.data());
  for (int i = 4; i < kShCoeffs; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(p[i * 3 + c], 0.0f);
}

TEST(Zh3, DegenerateAxisFallsBackToPlusZ) {
  Probe p{};
  for (int c = 0; c < 3; ++c) p[c] = 1.0f;
  float axis[3];
  zh3Axis(p.data(), axis);
  EXPECT_EQ(axis[0], 0.0f);
  EXPECT_EQ(axis[1], 0.0f);
  EXPECT_EQ(axis[2], 1.0f);
  // L1 that cancels in luminance: red up, green down with the weights' ratio.
  p[2 * 3 + 0] = 0.7152f;
  p[2 * 3 + 1] = -0.2126f;
  zh3Axis(p.data(), axis);
  EXPECT_EQ(axis[2], 1.0f);
  // Encoder and decoder agree: a zonal L2 around +z survives a stored-ZH3 round trip.
  p[6 * 3 + 0] = 0.2f;
  p[6 * 3 + 1] = 0.2f;
  p[6 * 3 + 2] = 0.2f;
  uint8_t rec[16];
  encodeProbeRecord(Representation::Zh3, p.data(), rec);
  Probe q{};
  ASSERT_TRUE(decodeProbeRecord(Representation::Zh3, rec, q.data()));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(q[6 * 3 + c], 0.2f, 0.01f);
}

TEST(Zh3, StoredBeatsHallucinatedOnLobes) {
  // Irradiance error of stored vs hallucinated ZH3 against full L2, on random multi-lobe probes.
  std::mt19937 rng(5);
  double errStored = 0, errHall = 0, errL1 = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Probe p = test::randomNonNegativeProbe(rng, 2, 0.05f);
    Probe stored = p, hall = p, l1 = p;
    float axis[3], zonal[3];
    zh3Axis(p.data(), axis);
    zh3Project(p.data(), axis, zonal);
    zh3ExpandToL2(stored.data(), axis, zonal);
    zh3HallucinateInPlace(hall.data());
    for (int i = 12; i < kProbeFloats; ++i) l1[i] = 0;
    for (int k = 0; k < 32; ++k) {
      float d[3], e[3], es[3], eh[3], e1[3];
      test::randomDirection(rng, d);
      shEvalIrradiance(p.data(), d[0], d[1], d[2], e);
      shEvalIrradiance(stored.data(), d[0], d[1], d[2], es);
      shEvalIrradiance(hall.data(), d[0], d[1], d[2], eh);
      shEvalIrradiance(l1.data(), d[0], d[1], d[2], e1);
      for (int c = 0; c < 3; ++c) {
        errStored += (es[c] - e[c]) * (es[c] - e[c]);
        errHall += (eh[c] - e[c]) * (eh[c] - e[c]);
        errL1 += (e1[c] - e[c]) * (e1[c] - e[c]);
      }
    }
  }
  EXPECT_LT(errStored, errHall);
  EXPECT_LT(errHall, errL1);
}

}  // namespace
}  // namespace probecast
