// Records: sizes, RGB9E5 and half known answers, ratio bounds, idempotence, bad values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "probecast/codec/half_float.h"
#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/record.h"
#include "probecast/codec/rgb9e5.h"
#include "probecast/codec/zh3.h"
#include "test_probes.h"

namespace probecast {
namespace {

using test::Probe;

TEST(Record, SizesAreExact) {
  EXPECT_EQ(recordSize(Representation::L1), 13u);
  EXPECT_EQ(recordSize(Representation::Zh3Hallucinated), 13u);
  EXPECT_EQ(recordSize(Representation::Zh3), 16u);
  EXPECT_EQ(recordSize(Representation::L2), 28u);
  EXPECT_EQ(recordSize(Representation::Fp16), 56u);
}

TEST(Record, RepresentationNamesRoundTrip) {
  for (Representation r : kAllRepresentations) EXPECT_EQ(parseRepresentation(representationName(r)), r);
  EXPECT_FALSE(parseRepresentation("l3").has_value());
}

TEST(Rgb9e5, KnownAnswers) {
  // docs/CODEC.md §8.5.
  const float a[3] = {1.0f, 0.5f, 0.25f};
  EXPECT_EQ(rgb9e5Encode(a), 0x81010100u);
  const float b[3] = {3.14159f, 1.0f, 0.001f};
  EXPECT_EQ(rgb9e5Encode(b), 0x88010192u);
  float out[3];
  rgb9e5Decode(0x88010192u, out);
  EXPECT_EQ(out[0], 3.140625f);
  EXPECT_EQ(out[1], 1.0f);
  EXPECT_EQ(out[2], 0.0f);
  const float z[3] = {0, 0, 0};
  EXPECT_EQ(rgb9e5Encode(z), 0u);
}

TEST(Rgb9e5, ClampsBadValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float in[3] = {nan, inf, -5.0f};
  float out[3];
  rgb9e5Decode(rgb9e5Encode(in), out);
  EXPECT_EQ(out[0], 0.0f);
  EXPECT_EQ(out[1], kRgb9e5Max);
  EXPECT_EQ(out[2], 0.0f);
}

TEST(Rgb9e5, LargestChannelRelativeErrorBound) {
  // 9-bit mantissa, round to nearest: relative error of the largest channel <= 2^-9 (mantissa >= 256).
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> e(-10.0f, 15.0f);
  for (int i = 0; i < 10000; ++i) {
    const float v = std::exp2(e(rng));
    const float in[3] = {v, v * 0.5f, v * 0.1f};
    float out[3];
    rgb9e5Decode(rgb9e5Encode(in), out);
    EXPECT_LE(std::fabs(out[0] - v) / v, 1.0f / 512.0f) << v;
  }
}

TEST(DcCode, IsMonotoneAndExactForEveryRgb9e5Value) {
  // Every channel value m·2^(e−24) survives value → code → value; codes order like values.
  for (uint32_t e = 0; e < 32; ++e) {
    uint16_t last = 0;
    for (uint32_t m = 0; m < 512; ++m) {
      float rgb[3];
      rgb9e5Decode(m | (e << 27), rgb);
      const uint16_t code = dcCodeFromValue(rgb[0]);
      EXPECT_EQ(dcValueFromCode(code), rgb[0]);
      EXPECT_GE(code, last);
      EXPECT_LE(code, kMaxDcCode);
      last = code;
    }
  }
  EXPECT_EQ(dcCodeFromValue(kRgb9e5Max), kMaxDcCode);
}

TEST(HalfFloat, KnownValuesAndRoundTrip) {
  EXPECT_EQ(floatToHalf(1.0f), 0x3c00);
  EXPECT_EQ(floatToHalf(-2.0f), 0xc000);
  EXPECT_EQ(floatToHalf(65504.0f), 0x7bff);
  EXPECT_EQ(floatToHalf(65520.0f), 0x7c00);           // rounds to Inf
  EXPECT_EQ(floatToHalf(std::exp2(-24.0f)), 0x0001);  // smallest subnormal
  EXPECT_EQ(floatToHalf(std::exp2(-25.0f)), 0x0000);  // ties to even → 0
  EXPECT_EQ(floatToHalf(1.0f + std::exp2(-11.0f)), 0x3c00);  // tie → even
  EXPECT_EQ(floatToHalf(1.0f + 3 * std::exp2(-11.0f)), 0x3c02);
  EXPECT_TRUE(std::isnan(halfToFloat(floatToHalf(std::numeric_limits<float>::quiet_NaN()))));
  for (uint32_t h = 0; h < 0x10000; ++h) {
    const float f = halfToFloat(static_cast<uint16_t>(h));
    if (std::isnan(f)) continue;
    EXPECT_EQ(floatToHalf(f), h) << std::hex << h;
  }
}

// Ratio of coefficient i of channel c to the DC.
float ratio(const Probe& p, int i, int c) { return p[i * 3 + c] / p[c]; }

TEST(RatioBounds, NonNegativeMixturesNeverBreakThem) {
  // docs/CODEC.md §3 / §8.6: for f >= 0 the ratios stay within the tight bounds.
  std::mt19937 rng(9);
  const float eps = 1e-5f;
  for (int trial = 0; trial < 5000; ++trial) {
    const Probe p = test::randomNonNegativeProbe(rng, 1 + trial % 6, trial % 3 == 0 ? 0.0f : 0.01f);
    float axis[3], zonal[3];
    zh3Axis(p.data(), axis);
    zh3Project(p.data(), axis, zonal);
    for (int c = 0; c < 3; ++c) {
      if (!(p[c] > 0)) continue;
      for (int i = 1; i <= 3; ++i) EXPECT_LE(std::fabs(ratio(p, i, c)), kBoundL1 + eps);
      for (int i : {4, 5, 7, 8}) EXPECT_LE(std::fabs(ratio(p, i, c)), kBoundL2Off + eps);
      EXPECT_GE(ratio(p, 6, c), kBoundL2ZeroLo - eps);
      EXPECT_LE(ratio(p, 6, c), kBoundL2ZeroHi + eps);
      const float r = (p[9 + c] * axis[0] + p[3 + c] * axis[1] + p[6 + c] * axis[2]) / p[c];
      const float c20 = zonal[c] / std::sqrt(4.0f * kPi / 5.0f) / p[c];
      EXPECT_GE(c20, std::sqrt(5.0f) * (r * r - 1.0f) / 2.0f - eps);
      EXPECT_LE(c20, std::sqrt(5.0f) + eps);
    }
  }
}

class RecordRoundTrip : public ::testing::TestWithParam<Representation> {};

TEST_P(RecordRoundTrip, EncodeDecodeEncodeIsEncode) {
  // docs/CODEC.md §8.6: encode∘decode∘encode = encode, decoding to the probe's function (for zh3h the
  // per-probe form: the per-pixel form's band is a correction, not the function).
  const Representation repr = GetParam();
  std::mt19937 rng(13);
  for (int trial = 0; trial < 2000; ++trial) {
    Probe p = test::randomNonNegativeProbe(rng, 1 + trial % 4, 0.02f);
    for (float& v : p) v *= std::exp2(static_cast<float>(trial % 20) - 8.0f);
    uint8_t a[kMaxRecordBytes], b[kMaxRecordBytes];
    encodeProbeRecord(repr, p.data(), a);
    Probe q{};
    ASSERT_TRUE(decodeProbeRecord(repr, a, q.data(), /*zh3PerPixel=*/false));
    encodeProbeRecord(repr, q.data(), b);
    ASSERT_EQ(0, std::memcmp(a, b, recordSize(repr))) << "trial " << trial;
  }
}

TEST_P(RecordRoundTrip, BadValuesEncodeToFiniteDocumentedProbes) {
  const Representation repr = GetParam();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  Probe p{};
  p[0] = nan;      // R DC NaN → R black
  p[1] = inf;      // G DC +Inf → saturates
  p[2] = -1.0f;    // B DC negative → B black
  p[4] = inf;      // G L1 +Inf ratio → clamped to the bound
  p[3] = nan;
  uint8_t rec[kMaxRecordBytes];
  encodeProbeRecord(repr, p.data(), rec);
  Probe q{};
  ASSERT_TRUE(decodeProbeRecord(repr, rec, q.data()));
  for (float v : q) EXPECT_TRUE(std::isfinite(v));
  if (repr == Representation::Fp16) {
    EXPECT_EQ(q[0], 0.0f);
    EXPECT_EQ(q[1], 65504.0f);
    EXPECT_EQ(q[2], -1.0f);
    return;
  }
  for (int i = 0; i < kShCoeffs; ++i) {
    EXPECT_EQ(q[i * 3 + 0], 0.0f) << "black R channel, coefficient " << i;
    EXPECT_EQ(q[i * 3 + 2], 0.0f) << "black B channel, coefficient " << i;
  }
  EXPECT_EQ(q[1], kRgb9e5Max);
  EXPECT_NEAR(q[4] / q[1], kBoundL1, 1e-6f);
}

TEST_P(RecordRoundTrip, BlackProbeDecodesToZero) {
  const Representation repr = GetParam();
  const Probe p{};
  uint8_t rec[kMaxRecordBytes];
  encodeProbeRecord(repr, p.data(), rec);
  Probe q;
  q.fill(1.0f);
  ASSERT_TRUE(decodeProbeRecord(repr, rec, q.data()));
  for (float v : q) EXPECT_EQ(v, 0.0f);
}

INSTANTIATE_TEST_SUITE_P(AllRepresentations, RecordRoundTrip, ::testing::ValuesIn(kAllRepresentations),
                         [](const auto& p) { return std::string(representationName(p.param)); });

TEST(Record, RatioErrorWithinHalfStep) {
  // docs/CODEC.md §4: worst-case ratio error ≈ 0.0068 (L1), 0.0076 (L2 m≠0), 0.0088 (zonal m=0).
  std::mt19937 rng(17);
  float worst[3] = {0, 0, 0};
  for (int trial = 0; trial < 3000; ++trial) {
    const Probe p = test::randomNonNegativeProbe(rng, 1 + trial % 5, 0.01f);
    uint8_t rec[28];
    encodeProbeRecord(Representation::L2, p.data(), rec);
    Probe q{};
    decodeProbeRecord(Representation::L2, rec, q.data());
    for (int c = 0; c < 3; ++c) {
      if (q[c] <= 0) continue;
      for (int i = 1; i < kShCoeffs; ++i) {
        const float err = std::fabs(q[i * 3 + c] - p[i * 3 + c]) / q[c];
        const int kind = i <= 3 ? 0 : (i == 6 ? 2 : 1);
        worst[kind] = std::max(worst[kind], err);
      }
    }
  }
  EXPECT_LE(worst[0], kBoundL1 / 254.0f + 1e-5f);
  EXPECT_LE(worst[1], kBoundL2Off / 254.0f + 1e-5f);
  EXPECT_LE(worst[2], (kBoundL2ZeroHi - kBoundL2ZeroLo) / 510.0f + 1e-5f);
  EXPECT_NEAR(kBoundL1 / 254.0f, 0.0068f, 1e-4f);
  EXPECT_NEAR(kBoundL2Off / 254.0f, 0.0076f, 1e-4f);
}

TEST(Record, OutOfRangeRatiosClampToBounds) {
  Probe p{};
  for (int c = 0; c < 3; ++c) p[c] = 1.0f;
  p[3] = 5.0f;    // L1 ratio 5 > √3
  p[12] = -9.0f;  // L2 m=-2 ratio −9 < −√15/2
  p[18] = -4.0f;  // L2 m=0 ratio −4 < −√5/2
  uint8_t rec[28];
  encodeProbeRecord(Representation::L2, p.data(), rec);
  Probe q{};
  decodeProbeRecord(Representation::L2, rec, q.data());
  EXPECT_NEAR(q[3], kBoundL1, 1e-5f);
  EXPECT_NEAR(q[12], -kBoundL2Off, 1e-5f);
  EXPECT_NEAR(q[18], kBoundL2ZeroLo, 1e-5f);
}

TEST(Record, Fp16RecordWithNanFailsToDecode) {
  uint8_t rec[56] = {};
  rec[1] = 0x7e;  // half 0x7e00 = NaN in coefficient 0
  Probe q{};
  EXPECT_FALSE(decodeProbeRecord(Representation::Fp16, rec, q.data()));
}

TEST(Record, QuantisedL2IrradianceWithinOnePercentOfFloat) {
  std::mt19937 rng(21);
  double num = 0, den = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Probe p = test::randomNonNegativeProbe(rng, 3, 0.1f);
    uint8_t rec[28];
    encodeProbeRecord(Representation::L2, p.data(), rec);
    Probe q{};
    decodeProbeRecord(Representation::L2, rec, q.data());
    for (int k = 0; k < 64; ++k) {
      float d[3], e[3], eq[3];
      test::randomDirection(rng, d);
      shEvalIrradiance(p.data(), d[0], d[1], d[2], e);
      shEvalIrradiance(q.data(), d[0], d[1], d[2], eq);
      for (int c = 0; c < 3; ++c) {
        num += (eq[c] - e[c]) * (eq[c] - e[c]);
        den += e[c] * e[c];
      }
    }
  }
  EXPECT_LT(std::sqrt(num / den), 0.01);
}


// The irradiance norm the zh3h choice minimises: ∫ |ΔE|² over the sphere, RGB pooled
// (irradiance_error.h), square-rooted.
double irradianceDistance(const float* a, const float* b) {
  double err = 0, energy = 0;
  irradianceErrorEnergy(a, b, err, energy);
  return std::sqrt(err);
}

// A bright ring around the equator and a weaker light at the pole: L1 points at the pole, where
// hallucinated ZH3 adds a peak, while the true L2 band is a negative zonal (the ring): plain L1
// is the better decoding of such a probe.
Probe ringProbe(std::mt19937& rng) {
  Probe p{};
  std::uniform_real_distribution<float> u(0.5f, 1.5f);
  const float white[3] = {1.0f, 1.0f, 1.0f};
  for (int k = 0; k < 12; ++k) {
    const float phi = 2.0f * kPi * static_cast<float>(k) / 12.0f;
    const Probe d = test::deltaProbe(std::cos(phi), std::sin(phi), 0.0f, white);
    const float w = u(rng);
    for (int i = 0; i < kProbeFloats; ++i) p[i] += w * d[i];
  }
  const float pole[3] = {u(rng) * 4.0f, u(rng) * 4.0f, u(rng) * 4.0f};
  const Probe d = test::deltaProbe(0.0f, 0.0f, 1.0f, pole);
  for (int i = 0; i < kProbeFloats; ++i) p[i] += d[i];
  return p;
}

// zh3h per probe (record.h): the decoder's result is hallucinated ZH3 or plain L1, whichever the
// encoder found nearer the probe's L2. Against the l1 record of the same probe it can only lose
// the one step the parity may cost: |zh3h − L2| ≤ |l1 − L2| + |one step| (triangle inequality),
// where a step of an L1 ratio is Â_1 · c00 · √3 / 127. Both choices occur on this mix, and over
// all probes zh3h is nearer than both l1 and every-probe hallucination (format 1).
TEST(Zh3hChoice, NeverFartherThanL1ByMoreThanOneStepAndBetterThanBoth) {
  std::mt19937 rng(11);
  int keptL1 = 0, hallucinated = 0;
  double sumChoice = 0, sumL1 = 0, sumAlways = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Probe p = trial % 2 ? ringProbe(rng) : test::randomNonNegativeProbe(rng, 1 + trial % 3, 0.1f);
    uint8_t zh3h[13], l1[13];
    encodeProbeRecord(Representation::Zh3Hallucinated, p.data(), zh3h);
    encodeProbeRecord(Representation::L1, p.data(), l1);
    float choice[kProbeFloats], plain[kProbeFloats];
    ASSERT_TRUE(decodeProbeRecord(Representation::Zh3Hallucinated, zh3h, choice));
    ASSERT_TRUE(decodeProbeRecord(Representation::L1, l1, plain));
    Probe always;  // format 1: every probe hallucinates from the l1 record's L1
    std::copy(plain, plain + kProbeFloats, always.begin());
    zh3HallucinateInPlace(always.data());
    float maxDc = 0;
    for (int c = 0; c < 3; ++c) maxDc = std::max(maxDc, plain[c]);
    const double step = kCosineBand[1] * maxDc * kBoundL1 / 127.0;
    const double eChoice = irradianceDistance(choice, p.data()), eL1 = irradianceDistance(plain, p.data());
    EXPECT_LE(eChoice, eL1 + step * 1.0001 + 1e-6) << "probe " << trial;
    bool band = false;
    for (int k = 12; k < kProbeFloats; ++k) band |= choice[k] != 0.0f;
    (band ? hallucinated : keptL1)++;
    sumChoice += eChoice;
    sumL1 += eL1;
    sumAlways += irradianceDistance(always.data(), p.data());
  }
  EXPECT_GT(keptL1, 40);
  EXPECT_GT(hallucinated, 40);
  EXPECT_LT(sumChoice, 0.95 * sumL1);
  EXPECT_LT(sumChoice, 0.95 * sumAlways);
}

// The choice travels in the parity of the L1 ratio bytes: odd decodes plain L1 (a zero L2 band),
// even hallucinates; the per-pixel form holds L1 and a band that, added to the renderer's
// hallucination of that L1, gives the per-probe result.
TEST(Zh3hChoice, ParityOfTheL1BytesChoosesAndThePerPixelFormAddsUp) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 100; ++trial) {
    const Probe p = trial % 2 ? ringProbe(rng) : test::randomNonNegativeProbe(rng, 2, 0.05f);
    uint8_t record[13];
    encodeProbeRecord(Representation::Zh3Hallucinated, p.data(), record);
    unsigned sum = 0;
    for (int j = 4; j < 13; ++j) sum += record[j];
    float perProbe[kProbeFloats], perPixel[kProbeFloats];
    ASSERT_TRUE(decodeProbeRecord(Representation::Zh3Hallucinated, record, perProbe, false));
    ASSERT_TRUE(decodeProbeRecord(Representation::Zh3Hallucinated, record, perPixel, true));
    Probe l1(p);
    std::copy(perPixel, perPixel + 12, l1.begin());
    for (int k = 12; k < kProbeFloats; ++k) l1[k] = 0.0f;
    Probe hallucinatedL1 = l1;
    zh3HallucinateInPlace(hallucinatedL1.data());
    for (int k = 0; k < 12; ++k) ASSERT_EQ(perProbe[k], perPixel[k]) << k;
    for (int k = 12; k < kProbeFloats; ++k) {
      EXPECT_EQ(perProbe[k], sum % 2 ? 0.0f : hallucinatedL1[k]) << "probe " << trial << ", coefficient " << k;
      EXPECT_NEAR(perPixel[k] + hallucinatedL1[k], perProbe[k], 1e-6f * (1.0f + std::fabs(hallucinatedL1[k])));
    }
  }
}

}  // namespace
}  // namespace probecast
