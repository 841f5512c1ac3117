// Records: sizes, RGB9E5 and half known answers, ratio bounds, idempotence, bad values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "probecast/codec/half_float.h"
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
  // CODEC.md §8.5.
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
  // CODEC.md §3 / §8.6: for f >= 0 the ratios stay within the tight bounds.
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
  // CODEC.md §8.6: encode∘decode∘encode = encode.
  const Representation repr = GetParam();
  std::mt19937 rng(13);
  for (int trial = 0; trial < 2000; ++trial) {
    Probe p = test::randomNonNegativeProbe(rng, 1 + trial % 4, 0.02f);
    for (float& v : p) v *= std::exp2(static_cast<float>(trial % 20) - 8.0f);
    uint8_t a[kMaxRecordBytes], b[kMaxRecordBytes];
    encodeProbeRecord(repr, p.data(), a);
    Probe q{};
    ASSERT_TRUE(decodeProbeRecord(repr, a, q.data(), /*zh3PerPixel=*/true));
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
  // CODEC.md §4: worst-case ratio error ≈ 0.0068 (L1), 0.0076 (L2 m≠0), 0.0088 (zonal m=0).
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

}  // namespace
}  // namespace probecast
