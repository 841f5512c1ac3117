// The probe volume every module shares (probe_volume.h): the default grid rule, checks, and the
// codec round trip with its one zh3h flag.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/probe_volume.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "test_probes.h"

namespace probecast {
namespace {

TEST(ProbeVolume, CellCentredGridPutsProbesHalfACellInsideTheBox) {
  // A 4 m box split into 4 cells along x: centres at 0.5, 1.5, 2.5, 3.5; one probe on y sits at
  // the box's middle; 2 cells on z over [-1, 1]: -0.5 and 0.5.
  const uint32_t dims[3] = {4, 1, 2};
  const float lo[3] = {0, 0, -1}, hi[3] = {4, 2, 1};
  const ProbeGrid g = cellCentredGrid(dims, lo, hi);
  EXPECT_FLOAT_EQ(g.bounds.min[0], 0.5f);
  EXPECT_FLOAT_EQ(g.bounds.max[0], 3.5f);
  EXPECT_FLOAT_EQ(g.bounds.min[1], 1.0f);
  EXPECT_FLOAT_EQ(g.bounds.max[1], 1.0f);
  EXPECT_FLOAT_EQ(g.bounds.min[2], -0.5f);
  EXPECT_FLOAT_EQ(g.bounds.max[2], 0.5f);
  float p[3];
  g.position(1 + 4 * (0 + 1 * 1), p);  // probe (1, 0, 1)
  EXPECT_FLOAT_EQ(p[0], 1.5f);
  EXPECT_FLOAT_EQ(p[1], 1.0f);
  EXPECT_FLOAT_EQ(p[2], 0.5f);
}

TEST(ProbeVolume, CheckRefusesWhatNoConsumerCanUse) {
  const ProbeVolume good = makeProbeVolume(ProbeGrid{{2, 2, 1}, {{0, 0, 0}, {1, 1, 0}}});
  std::string error;
  EXPECT_TRUE(checkProbeVolume(good, error)) << error;
  ProbeVolume v = good;
  v.probes[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(checkProbeVolume(v, error));
  EXPECT_NE(error.find("non-finite"), std::string::npos);
  v = good;
  v.active.pop_back();
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.active[0] = 7;
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.grid.bounds.max[0] = v.grid.bounds.min[0];  // two probes on one spot
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.grid.bounds.min[1] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.probes.push_back(0.0f);
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.grid.dims[2] = 0;
  EXPECT_FALSE(checkProbeVolume(v, error));
  v = good;
  v.noise.assign(4, 0.5f);  // one standard error per probe is fine
  EXPECT_TRUE(checkProbeVolume(v, error)) << error;
  v.noise.pop_back();
  EXPECT_FALSE(checkProbeVolume(v, error));
  EXPECT_NE(error.find("noise"), std::string::npos);
  for (float bad : {-1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    v.noise.assign(4, 0.5f);
    v.noise[2] = bad;
    EXPECT_FALSE(checkProbeVolume(v, error)) << bad;
  }
  v = good;
  v.stillUpdates.assign(4, 0);  // one count per probe is fine
  v.stillUpdates[1] = UINT32_MAX;
  EXPECT_TRUE(checkProbeVolume(v, error)) << error;
  v.stillUpdates.push_back(3);
  EXPECT_FALSE(checkProbeVolume(v, error));
  EXPECT_NE(error.find("stillUpdates"), std::string::npos) << error;
}

TEST(ProbeOffsets, CheckRefusesOffsetsNoViewerCanPlace) {
  // 3 × 2 × 1 probes over x in [0, 2], y in [0, 0.5]: cells 1 m and 0.5 m, z a single probe.
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 2, 1}, {{0, 0, 0}, {2, 0.5f, 0}}});
  std::string error;
  v.offsets.assign(18, 0.0f);
  v.offsets[0] = 0.5f;    // exactly half a cell is allowed
  v.offsets[4] = -0.25f;
  EXPECT_TRUE(checkProbeVolume(v, error)) << error;
  const auto refused = [&](size_t at, float value, const std::string& why) {
    ProbeVolume bad = v;
    bad.offsets[at] = value;
    EXPECT_FALSE(checkProbeVolume(bad, error)) << at << " " << value;
    EXPECT_NE(error.find(why), std::string::npos) << error;
  };
  refused(3, 0.5001f, "probe 1 moves");                         // beyond half of the 1 m cell along x
  refused(7, 0.2501f, "more than half its cell");               // beyond half of the 0.5 m cell along y
  refused(2, 1e-6f, "along z");                                 // z has one probe
  refused(9, std::numeric_limits<float>::quiet_NaN(), "non-finite x offset");
  refused(10, -std::numeric_limits<float>::infinity(), "non-finite y offset");
  v.offsets.pop_back();
  EXPECT_FALSE(checkProbeVolume(v, error));
  EXPECT_NE(error.find("17 floats for 6 probes"), std::string::npos) << error;
}

TEST(ProbeOffsets, QuantisedOffsetsAreWhatEveryViewerReconstructs) {
  const ProbeGrid g{{5, 3, 2}, {{-1.3f, 0.1f, 2.0f}, {2.9f, 1.7f, 2.7f}}};
  EXPECT_FLOAT_EQ(probeCellSize(g, 0), 1.05f);
  std::mt19937 rng(5);
  std::vector<float> o(g.count() * 3);
  for (size_t i = 0; i < o.size(); ++i) {
    const float half = 0.5f * probeCellSize(g, static_cast<int>(i % 3));
    o[i] = std::uniform_real_distribution<float>(-half, half)(rng);
  }
  std::string error;
  ASSERT_TRUE(checkProbeOffsets(g, o, error)) << error;
  std::vector<float> snapped = o;
  snapProbeOffsets(g, snapped);
  const std::vector<int8_t> q = quantizeProbeOffsets(g, o);
  std::vector<float> back;
  ASSERT_TRUE(dequantizeProbeOffsets(g, q.data(), q.size(), back, error)) << error;
  EXPECT_EQ(back, snapped);                         // the producer's snapped floats are the viewers', bit for bit
  EXPECT_EQ(quantizeProbeOffsets(g, snapped), q);   // and snapping is idempotent
  for (size_t i = 0; i < o.size(); ++i) {
    const float cell = probeCellSize(g, static_cast<int>(i % 3));
    const float step = cell / 256.0f;  // within half a step, or clamped to 127 steps
    EXPECT_LE(std::fabs(back[i] - o[i]), std::max(0.5f * step, std::fabs(o[i]) - 127.0f * step) + 1e-6f) << i;
    EXPECT_LT(std::fabs(back[i]), 0.5f * cell) << i;                            // ±127 steps: under half a cell
  }
  ASSERT_TRUE(checkProbeOffsets(g, back, error)) << error;
  // Bytes off the wire: wrong counts and -128 are refused, out unchanged.
  std::vector<int8_t> bad = q;
  bad.pop_back();
  EXPECT_FALSE(dequantizeProbeOffsets(g, bad.data(), bad.size(), back, error));
  EXPECT_NE(error.find("89 bytes for 30 probes"), std::string::npos) << error;
  bad = q;
  bad[7] = -128;
  EXPECT_FALSE(dequantizeProbeOffsets(g, bad.data(), bad.size(), back, error));
  EXPECT_NE(error.find("probe 2 y offset of -128"), std::string::npos) << error;
  EXPECT_EQ(back, snapped);
  EXPECT_TRUE(dequantizeProbeOffsets(g, nullptr, 0, back, error));
  EXPECT_TRUE(back.empty());
}

TEST(ProbeVolume, StreamLayoutOfAHugeGridIsInvalidNotWrapped) {
  ProbeGrid g{{65536 + 4, 4, 4}, {{0, 0, 0}, {1, 1, 1}}};  // 65540 would wrap to 4 in 16 bits
  EXPECT_FALSE(isValidLayout(streamLayoutFor(g, Representation::L1, 4)));
  g.dims[0] = 4;
  const StreamLayout layout = streamLayoutFor(g, Representation::Zh3, 2);
  EXPECT_TRUE(isValidLayout(layout));
  const ProbeGrid back = gridOf(layout, g.bounds);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(back.dims[a], g.dims[a]);
}

TEST(ProbeVolume, DecodeAsZh3hChoosesPerPixelOrPerProbeHallucination) {
  ProbeVolume v = makeProbeVolume(ProbeGrid{{1, 1, 1}, {{0, 0, 0}, {0, 0, 0}}});
  std::mt19937 rng(5);
  const test::Probe probe = test::randomNonNegativeProbe(rng, 1, 0.2f);
  std::copy(probe.begin(), probe.end(), v.probes.begin());
  const ProbeVolume perPixel = decodeAs(v, Representation::Zh3Hallucinated, /*zh3PerPixel=*/true);
  EXPECT_TRUE(perPixel.zh3PerPixel);
  ASSERT_TRUE(perPixel.decodedFrom.has_value());
  EXPECT_EQ(*perPixel.decodedFrom, Representation::Zh3Hallucinated);
  for (int k = 12; k < kProbeFloats; ++k) EXPECT_EQ(perPixel.probes[k], 0.0f) << k;  // hallucinates: band left to the shader
  const ProbeVolume perProbe = decodeAs(v, Representation::Zh3Hallucinated, false);
  EXPECT_FALSE(perProbe.zh3PerPixel);
  // Per probe: the hallucinated L2 band of the decoded L1, exactly as zh3.h makes it (this probe,
  // one lobe, is one the encoder lets hallucinate; record.h).
  std::vector<float> expected(perPixel.probes);
  zh3HallucinateInPlace(expected.data());
  for (int k = 0; k < kProbeFloats; ++k) EXPECT_EQ(perProbe.probes[k], expected[k]) << k;
  double l2 = 0;
  for (int k = 12; k < kProbeFloats; ++k) l2 += std::fabs(perProbe.probes[k]);
  EXPECT_GT(l2, 0.0);
  // Other representations never take the flag.
  EXPECT_FALSE(decodeAs(v, Representation::L2, /*zh3PerPixel=*/true).zh3PerPixel);
}

TEST(ProbeVolume, CodersCopyTheirVolumeWithGridAndRepresentation) {
  const ProbeGrid g{{4, 2, 2}, {{0, 0, 0}, {3, 1, 1}}};
  const StreamLayout layout = streamLayoutFor(g, Representation::Zh3Hallucinated, 2);
  StreamEncoder encoder(layout);
  StreamDecoder decoder(layout);
  std::mt19937 rng(9);
  std::vector<float> probes = test::movingLightFrame(static_cast<int>(g.count()), 0, 0.01f, rng);
  std::vector<uint8_t> active(g.count(), 1);
  active[3] = 0;
  encoder.update(probes.data(), active.data());
  std::vector<uint8_t> frame;
  encoder.writeKeyframeFrame(frame);
  ASSERT_EQ(decoder.apply(frame.data(), frame.size()), CodecStatus::Ok);
  ProbeVolume sent, held;
  encoder.copyVolume(g.bounds, sent);
  decoder.copyVolume(g.bounds, held);
  std::string error;
  EXPECT_TRUE(checkProbeVolume(held, error)) << error;
  EXPECT_EQ(held.probes, sent.probes);  // drift-free: the decoder holds the encoder's reconstruction
  EXPECT_EQ(held.active, active);
  EXPECT_EQ(held.grid.dims[0], 4u);
  EXPECT_EQ(held.grid.bounds.max[0], 3.0f);
  ASSERT_TRUE(held.decodedFrom.has_value());
  EXPECT_EQ(*held.decodedFrom, Representation::Zh3Hallucinated);
  EXPECT_FALSE(held.zh3PerPixel);
  StreamDecoder perPixel(layout);
  perPixel.setZh3PerPixel(true);
  ASSERT_EQ(perPixel.apply(frame.data(), frame.size()), CodecStatus::Ok);
  perPixel.copyVolume(g.bounds, held);
  EXPECT_TRUE(held.zh3PerPixel);
  for (size_t i = 0; i < held.probes.size(); ++i)
    if (i % kProbeFloats >= 12) {
      EXPECT_EQ(held.probes[i], 0.0f) << i;  // L1 only
    }
}

}  // namespace
}  // namespace probecast
