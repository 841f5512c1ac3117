// Brick versions, deltas, keyframes and the container: drift-free, golden bytes, masks, atomicity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "probecast/codec/crc32c.h"
#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "test_probes.h"

namespace probecast {
namespace {

StreamLayout makeLayout(uint16_t x, uint16_t y, uint16_t z, Representation repr, uint8_t brick = 4) {
  StreamLayout l;
  l.grid[0] = x;
  l.grid[1] = y;
  l.grid[2] = z;
  l.brickDim = brick;
  l.repr = repr;
  return l;
}

void expectSameState(const StreamEncoder& enc, const StreamDecoder& dec, const std::string& where) {
  const uint32_t n = probeCount(enc.layout());
  ASSERT_EQ(0, std::memcmp(enc.reconstruction(), dec.probes(), n * kProbeFloats * sizeof(float))) << where;
  ASSERT_EQ(0, std::memcmp(enc.activeMask(), dec.activeMask(), n)) << where;
  for (uint32_t b = 0; b < brickCount(enc.layout()); ++b) ASSERT_EQ(enc.brickVersion(b), dec.brickVersion(b)) << where;
}

struct DriftCase {
  Representation repr;
  int deadzone;
  float errorBound = 0.0f;  // per-brick representation
};

class DriftFree : public ::testing::TestWithParam<DriftCase> {};

TEST_P(DriftFree, DecoderMatchesEncoderOver1000NoisyFrames) {
  // 8×4×6 probes: 4 bricks, two of them cut at the z edge. Noise 3 % per coefficient, probes
  // switching between active and inactive, a subscriber joining late from keyframes.
  const auto [repr, deadzone, errorBound] = GetParam();
  const StreamLayout layout = makeLayout(8, 4, 6, repr);
  EncoderOptions options;
  options.deadzone = deadzone;
  options.errorBound = errorBound;
  StreamEncoder enc(layout, options);
  StreamDecoder dec(layout);
  std::unique_ptr<StreamDecoder> late;
  const int count = static_cast<int>(probeCount(layout));
  std::mt19937 rng(1234);
  std::vector<uint8_t> active(count, 1), frame;
  uint32_t switches = 0;  // versions that moved a brick to another representation (error bound)
  uint32_t riceDeltas = 0;
  for (int f = 0; f < 1000; ++f) {
    if (f % 50 == 0)
      for (int p = 0; p < count; ++p) active[p] = (rng() % 10) != 0;
    const std::vector<float> probes = test::movingLightFrame(count, f, 0.03f, rng);
    std::vector<uint32_t> before(brickCount(layout));
    for (uint32_t b = 0; b < before.size(); ++b) before[b] = enc.brickVersion(b);
    enc.update(probes.data(), active.data());
    for (uint32_t b = 0; b < before.size(); ++b) switches += enc.brickVersion(b) != before[b] && enc.deltaIsKeyframe(b);
    enc.writeChangedFrame(frame);
    for (size_t at = kFrameHeaderSize; at < frame.size();) {  // deltas stored raw whose differences are Rice codes
      SectionBytes b;
      ASSERT_TRUE(locateSection(frame.data() + at, frame.size() - at, &b));
      const uint8_t kind = frame[at + b.kindAt];
      riceDeltas += (kind & 0x07) == 0x02 && b.storedSize > 0 && (frame[at + b.dataAt] & 0x08) != 0;
      at += b.dataAt + b.storedSize;
    }
    ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok) << "frame " << f;
    expectSameState(enc, dec, "frame " + std::to_string(f));
    if (f == 500) {
      late = std::make_unique<StreamDecoder>(layout);
      enc.writeKeyframeFrame(frame);
      ASSERT_EQ(late->apply(frame.data(), frame.size()), CodecStatus::Ok);
    } else if (late) {
      ASSERT_EQ(late->apply(frame.data(), frame.size()), CodecStatus::Ok) << "late, frame " << f;
    }
    if (late) expectSameState(enc, *late, "late joiner, frame " + std::to_string(f));
  }
  if (errorBound > 0) EXPECT_GT(switches, 2u);  // the bound moved bricks between representations
  else EXPECT_EQ(switches, 0u);
  // Small differences went as Rice codes (format 4), so the checks above cover them too.
  EXPECT_GT(riceDeltas, 100u);
  // The reconstruction follows the input: DC within the dead-zone's reach of the last frame.
  const std::vector<float> last = test::movingLightFrame(count, 999, 0.0f, rng);
  double num = 0, den = 0;
  for (int p = 0; p < count; ++p) {
    if (!active[p]) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = enc.reconstruction()[p * kProbeFloats + c] - last[p * kProbeFloats + c];
      num += d * d;
      den += last[p * kProbeFloats + c] * last[p * kProbeFloats + c];
    }
  }
  EXPECT_LT(std::sqrt(num / den), 0.06 + 0.01 * deadzone);  // noise 3 % + quantisation + dead-zone
}

INSTANTIATE_TEST_SUITE_P(RepresentationsAndDeadzones, DriftFree,
                         ::testing::Values(DriftCase{Representation::L1, 0}, DriftCase{Representation::Zh3, 0},
                                           DriftCase{Representation::Zh3, 3}, DriftCase{Representation::L2, 0},
                                           DriftCase{Representation::L2, 2}, DriftCase{Representation::Fp16, 0},
                                           DriftCase{Representation::Zh3Hallucinated, 0},
                                           DriftCase{Representation::Zh3Hallucinated, 1},
                                           DriftCase{Representation::L2, 1, 0.05f}, DriftCase{Representation::Zh3, 0, 0.1f}),
                         [](const auto& p) {
                           return std::string(representationName(p.param.repr)) + "_dz" +
                                  std::to_string(p.param.deadzone) +
                                  (p.param.errorBound > 0 ? "_bound" + std::to_string(static_cast<int>(100 * p.param.errorBound))
                                                          : std::string());
                         });

// Luminance of c00 (Rec. 709), the unit of the encoder's noise values.
float dcLuminance(const float* probe) { return 0.2126f * probe[0] + 0.7152f * probe[1] + 0.0722f * probe[2]; }

TEST(Stream, NoiseRuleStaysDriftFreeOver1000Frames) {
  // Truth still for 300 frames, then drifting so slowly (1/400 of the way per frame) that no single
  // frame's change passes the threshold, then still again; the input is the truth plus noise of at
  // most σ/2 per coefficient (scaled per channel), σ stated per probe. What the decoder holds must stay within c·σ (irradiance-
  // weighted RMS) of what the input would decode to at every frame (it would drift away if the encoder compared each
  // input with the previous one), and bit-identical to the encoder's reconstruction.
  const StreamLayout layout = makeLayout(8, 4, 6, Representation::Zh3);
  EncoderOptions options;
  options.noiseScale = 2.0f;
  StreamEncoder enc(layout, options);
  StreamDecoder dec(layout);
  const int count = static_cast<int>(probeCount(layout));
  std::mt19937 rng(99);
  const std::vector<float> start = test::movingLightFrame(count, 0, 0.0f, rng);
  const std::vector<float> end = test::movingLightFrame(count, 12, 0.0f, rng);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<float> truth(start.size()), input(start.size()), sigma(count);
  std::vector<uint8_t> frameBytes;
  size_t stillBytes = 0;
  for (int f = 0; f < 1000; ++f) {
    const float a = std::clamp((static_cast<float>(f) - 300.0f) / 400.0f, 0.0f, 1.0f);
    for (size_t i = 0; i < truth.size(); ++i) truth[i] = (1.0f - a) * start[i] + a * end[i];
    for (int p = 0; p < count; ++p) {
      sigma[p] = 0.02f * dcLuminance(&truth[p * kProbeFloats]);
      const float* t = &truth[p * kProbeFloats];
      for (int i = 0; i < kProbeFloats; ++i)  // each channel's noise in proportion to its light
        input[p * kProbeFloats + i] = t[i] + 0.5f * sigma[p] * t[i % 3] / dcLuminance(t) * unit(rng);
    }
    enc.update(input.data(), nullptr, sigma.data());
    enc.writeChangedFrame(frameBytes);
    if (f >= 900) stillBytes += frameBytes.size();
    ASSERT_EQ(dec.apply(frameBytes.data(), frameBytes.size()), CodecStatus::Ok) << "frame " << f;
    expectSameState(enc, dec, "frame " + std::to_string(f));
    ProbeVolume sent = makeProbeVolume(ProbeGrid{{8, 4, 6}, {{0, 0, 0}, {1, 1, 1}}});
    sent.probes = input;
    const ProbeVolume fresh = decodeAs(sent, Representation::Zh3, false);  // what sending it would give
    for (int p = 0; p < count; ++p) {
      const float* have = dec.probes() + p * kProbeFloats;
      const float lum = dcLuminance(have);
      const float* want = fresh.probes.data() + p * kProbeFloats;
      double sum = 0, weights = 0;  // irradiance-weighted mean square, channels over their share
      for (int i = 0; i < kShCoeffs; ++i) {
        const double w = i == 0 ? 1.0 : i < 4 ? 4.0 / 9.0 : 1.0 / 16.0;
        for (int c = 0; c < 3; ++c) {
          const double d = (have[i * 3 + c] - want[i * 3 + c]) / (have[c] / lum);
          sum += w * d * d;
          weights += w;
        }
      }
      const double threshold = options.noiseScale * sigma[p];
      ASSERT_LE(std::sqrt(sum / weights), threshold * 1.0001 + 1e-6)
          << "frame " << f << " probe " << p;
      // Against the truth: the threshold, the noise and the 9-bit mantissa of the DC.
      const float truthLum = dcLuminance(&truth[p * kProbeFloats]);
      ASSERT_LE(std::fabs(lum - truthLum), (options.noiseScale + 1.0f) * sigma[p] * 1.1f + 0.004f * truthLum)
          << "frame " << f << " probe " << p;
    }
  }
  // Still again: noise within the threshold costs almost nothing (frame headers, a rare probe).
  EXPECT_LT(static_cast<double>(stillBytes) / 100.0 / count, 0.5);
}

// 128 grey probes: c00 = 1 in every channel and nothing else, but for the listed probes' c00.
std::vector<float> greyProbes(std::initializer_list<std::pair<int, float>> dc) {
  std::vector<float> p(128 * kProbeFloats, 0.0f);
  for (int i = 0; i < 128; ++i)
    for (int c = 0; c < 3; ++c) p[i * kProbeFloats + c] = 1.0f;
  for (const auto& [probe, value] : dc)
    for (int c = 0; c < 3; ++c) p[probe * kProbeFloats + c] = value;
  return p;
}

// A stream of grey probes (σ = 0.01 each) in an 8×4×4 zh3 layout of bricks of 4: step() encodes
// one update of greyProbes(dc), has the decoder apply its frame and follow bit for bit, and returns
// the bricks given a version (the sections of the frame).
struct GreyStream {
  StreamLayout layout = makeLayout(8, 4, 4, Representation::Zh3);
  StreamEncoder enc;
  StreamDecoder dec{layout};
  std::vector<float> noise = std::vector<float>(128, 0.01f);
  std::vector<uint32_t> stillUpdates;  // empty: none given
  std::vector<uint8_t> frame;
  std::string what;

  GreyStream(const EncoderOptions& options, std::string name) : enc(layout, options), what(std::move(name)) {}
  uint32_t step(std::initializer_list<std::pair<int, float>> dc) {
    const uint32_t changed = enc.update(greyProbes(dc).data(), nullptr, noise.data(),
                                        stillUpdates.empty() ? nullptr : stillUpdates.data());
    enc.writeChangedFrame(frame);
    EXPECT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok) << what;
    expectSameState(enc, dec, what);
    return changed;
  }
};

// The noise rule with a refinement interval: grey probes of c00 = 1 and σ = 0.01 (c = 2, so c·σ =
// 0.02). A DC change d moves the irradiance-weighted RMS of withinNoise by d·√(3/7.9375) = 0.615 d
// (DC weight 1 of 1 + 3·4/9 + 5/16 per channel): d = 0.05 (0.031) is a refinement, beyond c·σ and
// within 2c·σ; d = 0.1 (0.061) is new light. Two bricks (probe 0 and 1 in brick 0, probe 4 in brick
// 1). With an interval of 4, refinements wait for update 4 (its frame sequence a multiple of 4) and
// then both bricks' go in that one frame; new light goes at once. Without an interval all go at once.
TEST(Stream, RefinementsWaitForTheIntervalNewLightDoesNot) {
  for (uint32_t interval : {4u, 0u}) {
    EncoderOptions options;
    options.noiseScale = 2.0f;
    options.refinementInterval = interval;
    GreyStream stream(options, "interval " + std::to_string(interval));
    const StreamEncoder& enc = stream.enc;
    const StreamDecoder& dec = stream.dec;
    const auto step = [&](float probe0, float probe4, float probe1) {
      return stream.step({{0, probe0}, {4, probe4}, {1, probe1}});
    };
    EXPECT_EQ(step(1.0f, 1.0f, 1.0f), 2u);  // update 1: the first versions
    if (interval == 4) {
      EXPECT_EQ(step(1.05f, 1.0f, 1.0f), 0u);   // update 2: a refinement in brick 0 waits
      EXPECT_EQ(step(1.05f, 1.05f, 1.0f), 0u);  // update 3: and one in brick 1
      EXPECT_EQ(enc.brickVersion(0), 1u);
      EXPECT_EQ(step(1.05f, 1.05f, 1.0f), 2u);  // update 4: both go, in one frame
      EXPECT_EQ(enc.brickVersion(0), 2u);
      EXPECT_EQ(enc.brickVersion(1), 2u);
      EXPECT_NEAR(dec.probes()[0], 1.05f, 0.005f);
      EXPECT_NEAR(dec.probes()[4 * kProbeFloats], 1.05f, 0.005f);
      EXPECT_EQ(step(1.05f, 1.05f, 1.1f), 1u);  // update 5: new light on probe 1 goes at once
    } else {
      EXPECT_EQ(step(1.05f, 1.0f, 1.0f), 1u);  // each refinement goes at once
      EXPECT_EQ(step(1.05f, 1.05f, 1.0f), 1u);
      EXPECT_EQ(step(1.05f, 1.05f, 1.0f), 0u);
      EXPECT_EQ(step(1.05f, 1.05f, 1.1f), 1u);
    }
    EXPECT_EQ(enc.brickVersion(0), 3u);
    EXPECT_NEAR(dec.probes()[kProbeFloats], 1.1f, 0.005f);
  }
}

// A refinement is a change between c·σ and 2c·σ of a probe whose light held still for the whole
// refinement interval (ProbeVolume::stillUpdates). Where a probe's light changed more recently (the
// scene changed, or it restarted), such a change is the light moving on and goes at once. Same grey
// probes (c·σ = 0.02; DC steps of 0.05 are within 2c·σ), interval 4, every probe still for 100
// updates but probe 0 (brick 0), whose light changed: still for 2 updates at update 2, then 3, 4, 5.
// Brick 1 (probe 4) is still and waits for update 4 as before.
TEST(Stream, RefinementsOfProbesWhoseLightJustChangedGoAtOnce) {
  EncoderOptions options;
  options.noiseScale = 2.0f;
  options.refinementInterval = 4;
  GreyStream stream(options, "updates still");
  stream.stillUpdates.assign(128, 100);
  const auto step = [&](uint32_t still0, float probe0, float probe4) {
    stream.stillUpdates[0] = still0;
    return stream.step({{0, probe0}, {4, probe4}});
  };
  const auto held = [&](int probe) { return stream.dec.probes()[probe * kProbeFloats]; };
  EXPECT_EQ(step(100, 1.0f, 1.0f), 2u);  // update 1: the first versions
  EXPECT_EQ(step(2, 1.05f, 1.05f), 1u);  // update 2: probe 0's light changed: its change goes, probe 4's waits
  EXPECT_NEAR(held(0), 1.05f, 0.005f);
  EXPECT_NEAR(held(4), 1.0f, 0.005f);
  EXPECT_EQ(step(3, 1.1f, 1.05f), 1u);   // update 3: still for 3 < 4: at once
  EXPECT_NEAR(held(0), 1.1f, 0.005f);
  EXPECT_EQ(step(4, 1.1f, 1.05f), 1u);   // update 4: the interval: probe 4's goes
  EXPECT_NEAR(held(4), 1.05f, 0.005f);
  EXPECT_EQ(step(5, 1.15f, 1.05f), 0u);  // update 5: probe 0 still for 5 >= 4: it waits
  EXPECT_EQ(step(6, 1.15f, 1.05f), 0u);  // update 6
  EXPECT_EQ(step(7, 1.15f, 1.05f), 0u);  // update 7
  EXPECT_NEAR(held(0), 1.1f, 0.005f);
  EXPECT_EQ(step(8, 1.15f, 1.05f), 1u);  // update 8: goes with the interval
  EXPECT_NEAR(held(0), 1.15f, 0.005f);
}

// View weights (StreamEncoder::setViewWeights) on the grey probes above (σ = 0.01, c = 2; a DC change
// d moves the RMS by 0.615 d). Probe 4 weighs 0 (nobody sees it: held within 4c·σ = 0.08); probe 1
// weighs 64, whose scale (w̄/64)^(1/3) = 0.29 stops at the floor 0.5 (c·σ·0.5 = 0.01); the other 126
// weigh 1 (w̄ = 190/127 = 1.50, scale 1.14: 0.023). d = 0.1 (0.061) on probes 0 and 4: probe 0 goes,
// probe 4 is held; d = 0.03 (0.018) on probe 1 goes. Without weights probe 4 goes and probe 1 is
// held. Weights that are refused leave the ones set before.
TEST(Stream, ViewWeightsHoldWhatNobodySeesLonger) {
  for (bool weighted : {true, false}) {
    EncoderOptions options;
    options.noiseScale = 2.0f;
    GreyStream stream(options, weighted ? "weighted" : "plain");
    std::vector<float> w(128, 1.0f);
    w[4] = 0.0f;
    w[1] = 64.0f;
    if (weighted) {
      ASSERT_TRUE(stream.enc.setViewWeights(w));
      EXPECT_FALSE(stream.enc.setViewWeights(std::vector<float>(127, 1.0f)));  // not one per probe
      EXPECT_FALSE(stream.enc.setViewWeights(std::vector<float>(128, 0.0f)));  // nobody sees anything
      for (float bad : {-1.0f, NAN, INFINITY}) {
        std::vector<float> b(128, 1.0f);
        b[7] = bad;
        EXPECT_FALSE(stream.enc.setViewWeights(b)) << bad;
      }
    }
    EXPECT_EQ(stream.step({{0, 1.0f}, {4, 1.0f}, {1, 1.0f}}), 2u);
    stream.step({{0, 1.1f}, {4, 1.1f}, {1, 1.03f}});
    const float* held = stream.dec.probes();
    EXPECT_NEAR(held[0], 1.1f, 0.005f) << stream.what;
    EXPECT_NEAR(held[4 * kProbeFloats], weighted ? 1.0f : 1.1f, 0.005f) << stream.what;
    EXPECT_NEAR(held[1 * kProbeFloats], weighted ? 1.03f : 1.0f, 0.005f) << stream.what;
  }
  // Clearing them (an empty list) makes every probe alike again.
  EncoderOptions options;
  options.noiseScale = 2.0f;
  GreyStream stream(options, "cleared");
  std::vector<float> w(128, 1.0f);
  w[4] = 0.0f;
  ASSERT_TRUE(stream.enc.setViewWeights(w));
  ASSERT_TRUE(stream.enc.setViewWeights({}));
  stream.step({{4, 1.0f}});
  stream.step({{4, 1.1f}});
  EXPECT_NEAR(stream.dec.probes()[4 * kProbeFloats], 1.1f, 0.005f);
}

// Confirmations, on the probes of the test above (c·σ = 0.02; a DC change d moves the RMS by 0.615 d):
// d = 0.1 (0.061) is past c·σ but within 4c·σ (0.08), so with one confirmation it is kept for one
// update and sent on the second in a row; one update's excursion that comes back is never sent;
// d = 0.3 (0.18) is past 4c·σ, new light, sent at once. Without confirmations every change past c·σ
// goes on its first update. With a refinement interval of 4 as well, a confirmed refinement (d =
// 0.05) keeps its confirmation while it waits for update 4.
TEST(Stream, ConfirmationsKeepAOneUpdateExcursionNotNewLight) {
  for (uint32_t confirmations : {1u, 0u}) {
    EncoderOptions options;
    options.noiseScale = 2.0f;
    options.confirmations = confirmations;
    GreyStream stream(options, "confirmations " + std::to_string(confirmations));
    const StreamDecoder& dec = stream.dec;
    const auto step = [&](float probe0, float probe4) { return stream.step({{0, probe0}, {4, probe4}}); };
    const uint32_t kept = confirmations > 0 ? 0u : 1u;  // what a first update past c·σ sends
    EXPECT_EQ(step(1.0f, 1.0f), 2u);
    EXPECT_EQ(step(1.1f, 1.0f), kept);  // an excursion...
    EXPECT_EQ(step(1.0f, 1.0f), kept);  // ...that comes back: never sent with a confirmation
    EXPECT_NEAR(dec.probes()[0], 1.0f, 0.005f);
    EXPECT_EQ(step(1.1f, 1.0f), kept);  // the same change twice in a row
    EXPECT_EQ(step(1.1f, 1.0f), 1u - kept);
    EXPECT_NEAR(dec.probes()[0], 1.1f, 0.005f);
    EXPECT_EQ(step(1.1f, 1.0f), 0u);
    EXPECT_EQ(step(1.1f, 1.3f), 1u);  // new light: at once either way
    EXPECT_NEAR(dec.probes()[4 * kProbeFloats], 1.3f, 0.005f);
  }
  EncoderOptions options;
  options.noiseScale = 2.0f;
  options.confirmations = 1;
  options.refinementInterval = 4;
  GreyStream stream(options, "confirmations 1, interval 4");
  EXPECT_EQ(stream.step({{0, 1.0f}}), 2u);   // update 1
  EXPECT_EQ(stream.step({{0, 1.05f}}), 0u);  // update 2: not confirmed
  EXPECT_EQ(stream.step({{0, 1.05f}}), 0u);  // update 3: confirmed, a refinement: waits
  EXPECT_EQ(stream.step({{0, 1.05f}}), 1u);  // update 4: goes
  EXPECT_NEAR(stream.dec.probes()[0], 1.05f, 0.005f);
}

// Probes for the golden stream: deterministic, no randomness.
std::vector<float> goldenProbes(int frame) {
  std::vector<float> p(4 * kProbeFloats, 0.0f);
  for (int i = 0; i < 4; ++i) {
    float* q = p.data() + i * kProbeFloats;
    q[0] = 1.0f + 0.25f * static_cast<float>(i);
    q[1] = 0.5f;
    q[2] = 0.25f;
    q[3 * 3 + 0] = 0.3f;                    // R L1 toward +x
    q[2 * 3 + 1] = frame == 0 ? 0.2f : 0.1f;  // G L1 toward +z, changes in frame 1 (probe 2 only)
    if (frame == 1 && i != 2) q[2 * 3 + 1] = 0.2f;
  }
  return p;
}

std::string hex(const std::vector<uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (uint8_t b : bytes) {
    s.push_back(digits[b >> 4]);
    s.push_back(digits[b & 15]);
  }
  return s;
}

TEST(Stream, GoldenBytes) {
  // A 2×2×1 grid, one brick, l1, stored raw. Pins the format of stream.h (docs/CODEC.md §7) byte for
  // byte: frame 0 keyframe of 4 probes (probe 3 inactive), frame 1 delta of probe 2. CRCs are
  // CRC-32C (crc32c_test pins its known answers).
  // Derivation of the first record: DC (1, 0.5, 0.25) → RGB9E5 0x81010100 (docs/CODEC.md §8.5);
  // R ratio of c11: 0.3 / 1 / √3 · 127 = 22.0 → 0x16; G ratio of c10: 0.2 / 0.5 / √3 · 127 = 29.3 → 0x1d.
  const StreamLayout layout = makeLayout(2, 2, 1, Representation::L1, 2);
  EncoderOptions options;
  options.compress = false;
  StreamEncoder enc(layout, options);
  const uint8_t active[4] = {1, 1, 1, 0};
  std::vector<uint8_t> frame;
  enc.update(goldenProbes(0).data(), active);
  enc.writeKeyframeFrame(frame);
  const std::string keyframe = hex(frame);
  EXPECT_EQ(keyframe,
            "50524243" "04" "01" "02" "00" "0200" "0200" "0100" "0000"  // magic, version 4, l1, brick 2, grid
            "01000000" "01000000" "30000000" "993f5344"                 // frame 1, 1 section, 48 bytes, CRC
            "00" "01" "01" "28" "fa37e486"                              // brick 0, v1, keyframe raw, 40 bytes, CRC
            "07"                                                        // active mask: probes 0, 1, 2
            "004080" "010101" "010101" "818181"                         // RGB9E5 bytes 0..3, one plane each
            "000000" "000000" "000000"                                  // c1-1 R, G, B
            "000000" "1d1d1d" "000000"                                  // c10: G 0.4/√3·127 = 29.3
            "16120f" "000000" "000000");                                // c11: R 0.3/(1, 1.25, 1.5)/√3·127
  StreamDecoder dec(layout);
  ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
  enc.update(goldenProbes(1).data(), active);
  enc.writeChangedFrame(frame);
  ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
  // Delta: probe 2's G c10 ratio goes 0.2/0.5 → 0.1/0.5, symbol 29 → 15, zig-zag(−14) = 27 = 0x1b.
  // The active set is the base's (no mask), one changed probe of four is a one-byte mask (a list
  // would take two). Its 12 differences as Rice codes (rice_code.h) take 5 bytes, byte planes 12:
  // k = 0 for both classes (the narrow ones cost 24 bits at k = 0, 32 at 1, 33 at 2), then per value
  // a 0 bit for each zero and, for 27 (quotient 27 ≥ 8), the escape's eight 1 bits and 27 in 8 bits.
  // Low bit first: bits 0-6 the two parameters, 7-9 the DC zeros, 10-13 four ratio zeros, 14-21 the
  // escape, 22-29 27 = 11011000, 30-33 four zeros: 00 c0 ff 06 00.
  const std::string delta = hex(frame);
  EXPECT_EQ(delta,
            "50524243" "04" "01" "02" "00" "0200" "0200" "0100" "0000"
            "02000000" "01000000" "0f000000" "533dc4c6"
            "00" "02" "02" "07" "40ce4dd3"                              // brick 0, v2, delta raw, 7 bytes, CRC
            "08"                                                        // form: Rice codes
            "04"                                                        // changed mask: probe 2
            "00c0ff0600");                                              // the differences
  // The same two frames as format 3 wrote them (pinned when it was current: the differences in
  // byte planes, one byte per DC difference) still decode, to the same state; a format 3 frame with
  // the Rice form is refused (format 3 knew no such form bit).
  const auto bytes = [](const std::string& h) {
    std::vector<uint8_t> out;
    for (size_t i = 0; i + 1 < h.size(); i += 2) out.push_back(static_cast<uint8_t>(std::stoi(h.substr(i, 2), nullptr, 16)));
    return out;
  };
  const std::vector<uint8_t> v3Keyframe = bytes(
      "50524243" "03" "01" "02" "00" "0200" "0200" "0100" "0000" "01000000" "01000000" "30000000" "20e9886d"
      "00" "01" "01" "28" "fa37e486" "07" "004080" "010101" "010101" "818181" "000000" "000000" "000000" "000000"
      "1d1d1d" "000000" "16120f" "000000" "000000");
  const std::vector<uint8_t> v3Delta = bytes(
      "50524243" "03" "01" "02" "00" "0200" "0200" "0100" "0000" "02000000" "01000000" "16000000" "89937a2d"
      "00" "02" "02" "0e" "b00b5e65" "04" "04" "00" "00" "00" "000000" "00" "1b" "00" "000000");
  StreamDecoder third(layout);
  ASSERT_EQ(third.apply(v3Keyframe.data(), v3Keyframe.size()), CodecStatus::Ok);
  ASSERT_EQ(third.apply(v3Delta.data(), v3Delta.size()), CodecStatus::Ok);
  expectSameState(enc, third, "format 3 frames");
  std::vector<uint8_t> riceAsV3 = frame;
  riceAsV3[4] = 3;
  rewriteFrameChecksums(riceAsV3);
  StreamDecoder strict(layout);
  ASSERT_EQ(strict.apply(v3Keyframe.data(), v3Keyframe.size()), CodecStatus::Ok);
  EXPECT_EQ(strict.apply(riceAsV3.data(), riceAsV3.size()), CodecStatus::NonCanonical);
  EXPECT_EQ(strict.brickVersion(0), 1u);
  // Format 3's byte planes in a format 4 frame: format 4's other spelling of the same delta.
  std::vector<uint8_t> planesAsV4 = v3Delta;
  planesAsV4[4] = 4;
  rewriteFrameChecksums(planesAsV4);
  EXPECT_EQ(strict.apply(planesAsV4.data(), planesAsV4.size()), CodecStatus::Ok);
  expectSameState(enc, strict, "format 3 byte planes in a format 4 frame");
  // As format 2 wrote them (pinned when it was current: 22-byte section headers, and a delta with
  // both masks and both bytes of each DC difference) they still decode, to the same state; and as
  // format 1 wrote them (only the version byte and the header CRC differ, l1 being unchanged by
  // format 2).
  const std::string v2KeyframeHex =
      "50524243" "02" "01" "02" "00" "0200" "0200" "0100" "0000" "01000000" "01000000" "3e000000" "3a5ac6e5"
      "00000000" "01000000" "01" "00" "28000000" "28000000" "5a83f9fe"  // brick 0 v1 keyframe raw
      "07" "004080" "010101" "010101" "818181" "000000" "000000" "000000" "000000" "1d1d1d" "000000" "16120f"
      "000000" "000000";
  const std::vector<uint8_t> v2Keyframe = bytes(v2KeyframeHex);
  const std::vector<uint8_t> v2Delta = bytes(
      "50524243" "02" "01" "02" "00" "0200" "0200" "0100" "0000" "02000000" "01000000" "27000000" "095e3174"
      "00000000" "02000000" "02" "00" "11000000" "11000000" "33b2653c"  // brick 0 v2 delta raw
      "07" "04" "0000" "0000" "0000" "000000" "00" "1b" "00" "000000");
  StreamDecoder second(layout);
  ASSERT_EQ(second.apply(v2Keyframe.data(), v2Keyframe.size()), CodecStatus::Ok);
  ASSERT_EQ(second.apply(v2Delta.data(), v2Delta.size()), CodecStatus::Ok);
  expectSameState(enc, second, "format 2 frames");
  const std::vector<uint8_t> v1Keyframe = bytes(
      "5052424301010200020002000100000001000000010000003e000000596bfa2e0000000001000000010028000000280000005a83f9fe07"
      "0040800101010101018181810000000000000000000000001d1d1d00000016120f000000000000");
  const std::vector<uint8_t> v1Delta = bytes(
      "505242430101020002000200010000000200000001000000270000006a6f0dbf00000000020000000200110000001100000033b2653c07"
      "04000000000000000000001b00000000");
  EXPECT_EQ(hex(v1Keyframe).substr(10),
            v2KeyframeHex.substr(10, 46) + hex(v1Keyframe).substr(56, 8) + v2KeyframeHex.substr(64));
  StreamDecoder old(layout);
  ASSERT_EQ(old.apply(v1Keyframe.data(), v1Keyframe.size()), CodecStatus::Ok);
  ASSERT_EQ(old.apply(v1Delta.data(), v1Delta.size()), CodecStatus::Ok);
  expectSameState(enc, old, "format 1 frames");
}

// Unsigned LEB128, as stream.h states it; returns the bytes it took.
size_t getVarintForTest(const uint8_t* p, size_t size, uint32_t* v) {
  uint32_t value = 0;
  for (size_t i = 0; i < size && i < 5; ++i) {
    value |= static_cast<uint32_t>(p[i] & 0x7f) << (7 * i);
    if (!(p[i] & 0x80)) {
      *v = value;
      return i + 1;
    }
  }
  ADD_FAILURE() << "not a varint";
  return size;
}

// A frame of raw keyframe sections as formats 1 and 2 spelled it (22-byte section headers; keyframe
// payloads are the same in every format), with `version` in its header.
std::vector<uint8_t> asFixedFormat(const std::vector<uint8_t>& frame, uint8_t version) {
  std::vector<uint8_t> out(frame.begin(), frame.begin() + kFrameHeaderSize);
  out[4] = version;
  size_t at = kFrameHeaderSize;
  const auto put32 = [&out](uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<uint8_t>(v >> (8 * b)));
  };
  while (at < frame.size()) {
    SectionBytes b;
    EXPECT_TRUE(locateSection(frame.data() + at, frame.size() - at, &b));
    const uint8_t kind = frame[at + b.kindAt];
    EXPECT_EQ(kind & 0x0f, 1) << "keyframes only";
    EXPECT_EQ(kind & 0x04, 0) << "raw sections only";
    uint32_t brick = 0, brickVersion = 0;
    const size_t n = getVarintForTest(frame.data() + at, b.kindAt, &brick);
    getVarintForTest(frame.data() + at + n, b.kindAt - n, &brickVersion);
    put32(brick);
    put32(brickVersion);
    out.push_back(kind);
    out.push_back(0);  // raw
    put32(b.storedSize);
    put32(b.storedSize);
    put32(0);  // CRC, below
    out.insert(out.end(), frame.begin() + at + b.dataAt, frame.begin() + at + b.dataAt + b.storedSize);
    at += b.dataAt + b.storedSize;
  }
  const uint32_t sectionBytes = static_cast<uint32_t>(out.size() - kFrameHeaderSize);
  for (int b = 0; b < 4; ++b) out[24 + b] = static_cast<uint8_t>(sectionBytes >> (8 * b));
  rewriteFrameChecksums(out);
  return out;
}

// Format 1 zh3h frames decode as format 1 meant them: every probe hallucinates, whatever the
// parity of its L1 bytes; the same sections in a format 2 or later frame decode per probe as chosen.
// Versions outside 1..4 are refused.
TEST(Stream, Format1Zh3hFramesHallucinateEveryProbe) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::Zh3Hallucinated);
  std::mt19937 rng(21);
  std::vector<float> probes;
  for (int p = 0; p < 64; ++p) {
    const test::Probe q = test::randomNonNegativeProbe(rng, 1 + p % 3, 0.05f);
    probes.insert(probes.end(), q.begin(), q.end());
  }
  EncoderOptions raw;
  raw.compress = false;
  StreamEncoder enc(layout, raw);
  enc.update(probes.data(), nullptr);
  std::vector<uint8_t> frame;
  enc.writeKeyframeFrame(frame);
  StreamDecoder current(layout);
  ASSERT_EQ(current.apply(frame.data(), frame.size()), CodecStatus::Ok);
  expectSameState(enc, current, "format 4");
  const std::vector<uint8_t> v2 = asFixedFormat(frame, 2);
  StreamDecoder second(layout);
  ASSERT_EQ(second.apply(v2.data(), v2.size()), CodecStatus::Ok);
  expectSameState(enc, second, "format 2");
  const auto withVersion = [&frame](uint8_t version) {
    std::vector<uint8_t> f = frame;
    f[4] = version;
    const uint32_t crc = crc32c(f.data(), 28);
    for (int b = 0; b < 4; ++b) f[28 + b] = static_cast<uint8_t>(crc >> (8 * b));
    return f;
  };
  const std::vector<uint8_t> v1 = asFixedFormat(frame, 1);
  StreamDecoder old(layout);
  ASSERT_EQ(old.apply(v1.data(), v1.size()), CodecStatus::Ok);
  int plainL1 = 0;
  for (int p = 0; p < 64; ++p) {
    std::vector<float> expected(current.probes() + p * kProbeFloats, current.probes() + (p + 1) * kProbeFloats);
    bool band = false;
    for (int k = 12; k < kProbeFloats; ++k) band |= expected[k] != 0.0f;
    plainL1 += band ? 0 : 1;
    zh3HallucinateInPlace(expected.data());  // from the same L1
    for (int k = 0; k < kProbeFloats; ++k) ASSERT_EQ(old.probes()[p * kProbeFloats + k], expected[k]) << p << "," << k;
  }
  EXPECT_GT(plainL1, 0);  // format 2 kept some probes at plain L1, which format 1 hallucinates
  for (uint8_t version : {uint8_t{0}, static_cast<uint8_t>(kFormatVersion + 1)}) {
    const std::vector<uint8_t> f = withVersion(version);
    StreamDecoder dec(layout);
    EXPECT_EQ(dec.apply(f.data(), f.size()), CodecStatus::UnsupportedVersion) << int(version);
  }
}

// Rice codes as stream.h states them, written here apart from the codec's own writer: per value, its
// quotient v >> k in unary (ones, then a zero) and its k low bits, or at a quotient of 8 or more
// eight ones and the value in full (16 bits wide, 8 narrow); bits low first in each byte.
struct TestBits {
  std::vector<uint8_t> bytes;
  size_t bit = 0;
  void put(uint32_t v, int n) {
    for (int i = 0; i < n; ++i, ++bit) {
      if (bit % 8 == 0) bytes.push_back(0);
      bytes.back() = static_cast<uint8_t>(bytes.back() | (((v >> i) & 1u) << (bit % 8)));
    }
  }
  void rice(uint32_t v, int k, int full) {
    if ((v >> k) >= 8) {
      put(0xff, 8);
      put(v, full);
    } else {
      put((1u << (v >> k)) - 1u, static_cast<int>(v >> k) + 1);
      put(v, k);
    }
  }
};
int testRiceBits(const std::vector<uint32_t>& values, int k, int full) {
  int bits = 0;
  for (uint32_t v : values) bits += (v >> k) >= 8 ? 8 + full : static_cast<int>(v >> k) + 1 + k;
  return bits;
}
int testBestRiceK(const std::vector<uint32_t>& values, int kinds, int full) {
  int best = 0;
  for (int k = 1; k < kinds; ++k)
    if (testRiceBits(values, k, full) < testRiceBits(values, best, full)) best = k;
  return best;
}
// One probe's differences (3 wide, then the narrow ones) as a format 4 delta spells them, with the
// parameters given.
std::vector<uint8_t> testRice(const std::vector<uint32_t>& wide, const std::vector<uint32_t>& narrow, int wideK,
                              int narrowK) {
  TestBits b;
  b.put(static_cast<uint32_t>(wideK), 4);
  b.put(static_cast<uint32_t>(narrowK), 3);
  for (uint32_t v : wide) b.rice(v, wideK, 16);
  for (uint32_t v : narrow) b.rice(v, narrowK, 8);
  return b.bytes;
}

// A delta is spelled in its shortest form (stream.h): the active mask only when it changed, the
// changed probes as a list when that is shorter than a mask (bricks of at most 256 probes); the
// differences in format 4 as Rice codes only when those are shorter than byte planes (the encoder
// then stores whichever section is shorter), in byte planes always in format 3, the DC differences
// in one byte when they fit. Each form round-trips; any
// other spelling of the same change (a probe listed with nothing changed among them, Rice codes under
// a parameter that is not the best, padding bits set), and a varint header number not in its
// shortest form, is refused and changes nothing. Format 3 frames in byte planes still decode.
TEST(Stream, DeltaFormsRoundTripAndOnlyTheShortestIsRead) {
  for (const uint8_t brickDim : {uint8_t{4}, uint8_t{8}}) {  // 64 probes (8 mask bytes); 512 (64, no lists)
    SCOPED_TRACE(testing::Message() << "brick " << int(brickDim));
    const StreamLayout layout = makeLayout(brickDim, brickDim, brickDim, Representation::L1, brickDim);
    const uint32_t n = probeCount(layout), mbytes = n / 8;
    EncoderOptions options;
    options.compress = false;
    StreamEncoder enc(layout, options);
    StreamDecoder dec(layout);
    std::vector<float> probes(n * kProbeFloats, 0.0f);
    for (uint32_t p = 0; p < n; ++p) {
      probes[p * kProbeFloats + 0] = probes[p * kProbeFloats + 1] = probes[p * kProbeFloats + 2] = 1.0f;
      probes[p * kProbeFloats + 9] = 0.2f;
    }
    std::vector<uint8_t> active(n, 1), frame;
    enc.update(probes.data(), active.data());
    enc.writeKeyframeFrame(frame);
    ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
    // The form byte of each delta, and the decoder's state after it.
    const auto step = [&]() {
      EXPECT_EQ(enc.update(probes.data(), active.data()), 1u);
      enc.writeChangedFrame(frame);
      EXPECT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
      expectSameState(enc, dec, "after a delta");
      SectionBytes b;
      EXPECT_TRUE(locateSection(frame.data() + kFrameHeaderSize, frame.size() - kFrameHeaderSize, &b));
      return frame[kFrameHeaderSize + b.dataAt];
    };
    const bool lists = n <= 256;
    probes[5 * kProbeFloats + 9] = 0.1f;  // one ratio of probe 5
    EXPECT_EQ(step(), lists ? 0x0a : 0x08);  // Rice codes; a list of one where a list is allowed
    const std::vector<uint8_t> oneProbe = frame;
    for (uint32_t p = 0; p < 12; ++p) probes[p * kProbeFloats + 9] = 0.3f;
    EXPECT_EQ(step(), 0x08);  // 12 probes: a mask is shorter than 1 + 12 bytes
    probes[7 * kProbeFloats + 1] = 40.0f;  // G of probe 7's DC: a code difference past one byte
    EXPECT_EQ(step(), lists ? 0x0a : 0x08);
    active[9] = 0;
    EXPECT_EQ(step(), lists ? 0x07 : 0x05);  // the active mask changed: spelled out; no differences
    active[9] = 1;
    EXPECT_EQ(step(), lists ? 0x0b : 0x09);  // probe 9 back from black
    // Every probe's DC up by up to 49 % (DC code differences 0..125, rgb9e5.h) and every ratio to a
    // value of its own: differences spread over the whole byte, which Rice codes spell longer than
    // byte planes.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> ratio(-1.6f, 1.6f), gain(1.0f, 1.49f);
    for (uint32_t p = 0; p < n; ++p) {
      for (int c = 0; c < 3; ++c) probes[p * kProbeFloats + c] *= gain(rng);
      for (int c = 3; c < 12; ++c) probes[p * kProbeFloats + c] = ratio(rng) * probes[p * kProbeFloats + c % 3];
    }
    EXPECT_EQ(step(), 0x04);  // byte planes, the DC differences in one byte

    // Re-spellings of the one-probe delta (brick 0, version 2 over version 1), each against a
    // decoder that holds version 1, in a frame of the given format.
    SectionBytes b;
    ASSERT_TRUE(locateSection(oneProbe.data() + kFrameHeaderSize, oneProbe.size() - kFrameHeaderSize, &b));
    const std::vector<uint8_t> data(oneProbe.begin() + kFrameHeaderSize + b.dataAt, oneProbe.end());
    const auto applied = [&](const std::vector<uint8_t>& section, uint8_t version = kFormatVersion) {
      StreamEncoder base(layout, options);
      std::vector<float> first = probes;
      for (uint32_t p = 0; p < n; ++p) {
        for (int c = 0; c < kProbeFloats; ++c) first[p * kProbeFloats + c] = c < 3 ? 1.0f : 0.0f;
        first[p * kProbeFloats + 9] = 0.2f;
      }
      std::vector<uint8_t> key;
      base.update(first.data(), nullptr);
      base.writeKeyframeFrame(key);
      StreamDecoder fresh(layout);
      EXPECT_EQ(fresh.apply(key.data(), key.size()), CodecStatus::Ok);
      std::vector<uint8_t> f;
      const std::span<const uint8_t> sections[] = {section};
      writeFrame(layout, 2, sections, f);
      f[4] = version;
      rewriteFrameChecksums(f);
      const CodecStatus st = fresh.apply(f.data(), f.size());
      if (st != CodecStatus::Ok) {
        EXPECT_EQ(fresh.brickVersion(0), 1u);  // refused whole
      } else {
        EXPECT_EQ(fresh.brickVersion(0), 2u);
      }
      return st;
    };
    ASSERT_EQ(applied(sealSection(0, 2, 0x02, data)), CodecStatus::Ok);
    // Probe 5's differences from its records (record.h: 4 RGB9E5 bytes, then the 9 ratio bytes): the
    // DC is unchanged, one ratio moved.
    float before[kProbeFloats] = {1.0f, 1.0f, 1.0f}, after[kProbeFloats] = {1.0f, 1.0f, 1.0f};
    before[9] = 0.2f;
    after[9] = 0.1f;
    uint8_t recordBefore[kMaxRecordBytes], recordAfter[kMaxRecordBytes];
    encodeProbeRecord(Representation::L1, before, recordBefore);
    encodeProbeRecord(Representation::L1, after, recordAfter);
    const std::vector<uint32_t> wideZ = {0, 0, 0};
    std::vector<uint32_t> narrowZ;
    for (int j = 4; j < 13; ++j) {
      const int d = static_cast<int8_t>(static_cast<uint8_t>(recordAfter[j] - recordBefore[j]));
      narrowZ.push_back(static_cast<uint32_t>(d >= 0 ? 2 * d : -2 * d - 1));
    }
    const int bestNarrow = testBestRiceK(narrowZ, 8, 8);
    const std::vector<uint8_t> rice = testRice(wideZ, narrowZ, 0, bestNarrow);
    const std::vector<uint8_t> changed = lists ? std::vector<uint8_t>{0x01, 0x05} : [&] {
      std::vector<uint8_t> mask(mbytes, 0);
      mask[0] = 1 << 5;
      return mask;
    }();
    const uint8_t listBit = lists ? 0x02 : 0x00;
    const auto payload = [](std::initializer_list<std::vector<uint8_t>> parts) {
      std::vector<uint8_t> out;
      for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
      return out;
    };
    // The encoder's spelling, written here from the format: form, changed probes, Rice codes.
    EXPECT_EQ(data, payload({{static_cast<uint8_t>(0x08 | listBit)}, changed, rice}));
    const auto delta = [&](uint8_t form, const std::vector<uint8_t>& differences) {
      return sealSection(0, 2, 0x02, payload({{static_cast<uint8_t>(form | listBit)}, changed, differences}));
    };
    // The same change in byte planes (DC differences in one byte, then the ratios): format 3's only
    // spelling, and format 4's other (the encoder's choice, as compression is: byte planes compress
    // where Rice codes do not); and both bytes of each DC difference, every high byte zero, which
    // neither reads.
    std::vector<uint8_t> planes = {0, 0, 0};
    for (uint32_t z : narrowZ) planes.push_back(static_cast<uint8_t>(z));
    ASSERT_LT(rice.size(), planes.size());
    EXPECT_EQ(applied(delta(0x04, planes), 3), CodecStatus::Ok);
    EXPECT_EQ(applied(delta(0x04, planes)), CodecStatus::Ok);
    std::vector<uint8_t> wideBoth(6, 0);
    for (uint32_t z : narrowZ) wideBoth.push_back(static_cast<uint8_t>(z));
    EXPECT_EQ(applied(delta(0x00, wideBoth), 3), CodecStatus::NonCanonical);
    EXPECT_EQ(applied(delta(0x00, wideBoth)), CodecStatus::NonCanonical);
    // Format 3 knew no Rice form.
    EXPECT_EQ(applied(sealSection(0, 2, 0x02, data), 3), CodecStatus::NonCanonical);
    // Rice codes under parameters that are not the best, with a padding bit set, or a byte after.
    EXPECT_EQ(applied(delta(0x08, testRice(wideZ, narrowZ, 1, bestNarrow))), CodecStatus::NonCanonical);
    EXPECT_EQ(applied(delta(0x08, testRice(wideZ, narrowZ, 0, bestNarrow + 1))), CodecStatus::NonCanonical);
    std::vector<uint8_t> padded = rice;
    const int usedBits = 7 + testRiceBits(wideZ, 0, 16) + testRiceBits(narrowZ, bestNarrow, 8);
    ASSERT_NE(usedBits % 8, 0) << "the spelling has padding bits";
    padded.back() = static_cast<uint8_t>(padded.back() | 0x80);
    EXPECT_EQ(applied(delta(0x08, padded)), CodecStatus::NonCanonical);
    std::vector<uint8_t> longer = rice;
    longer.push_back(0);
    EXPECT_EQ(applied(delta(0x08, longer)), CodecStatus::NonCanonical);
    EXPECT_EQ(applied(delta(0x08, std::vector<uint8_t>(rice.begin(), rice.end() - 1))), CodecStatus::NonCanonical);
    // Rice codes together with the one-byte-DC bit, and an unknown form bit.
    EXPECT_EQ(applied(delta(0x0c, rice)), CodecStatus::NonCanonical);
    EXPECT_EQ(applied(delta(0x18, rice)), CodecStatus::NonCanonical);
    // The base's active set spelled out.
    std::vector<uint8_t> activeAll(mbytes, 0xff);
    EXPECT_EQ(applied(sealSection(0, 2, 0x02, payload({{static_cast<uint8_t>(0x09 | listBit)}, activeAll, changed, rice}))),
              CodecStatus::NonCanonical);
    // A mask where a list is shorter (brick of 64), or a list where none is allowed (512).
    if (lists) {
      std::vector<uint8_t> mask(mbytes, 0);
      mask[0] = 1 << 5;
      EXPECT_EQ(applied(sealSection(0, 2, 0x02, payload({{0x08}, mask, rice}))), CodecStatus::NonCanonical);
    } else {
      EXPECT_EQ(applied(sealSection(0, 2, 0x02, payload({{0x0a, 0x01, 0x05}, rice}))), CodecStatus::NonCanonical);
    }
    // The probe listed with nothing changed: the base state, spelled as a delta that changes it.
    const std::vector<uint32_t> noWide = {0, 0, 0}, noNarrow(narrowZ.size(), 0);
    EXPECT_EQ(applied(delta(0x08, testRice(noWide, noNarrow, 0, 0))), CodecStatus::NonCanonical);
    if (lists) {  // a list that does not increase
      EXPECT_EQ(applied(sealSection(0, 2, 0x02, payload({{0x0a, 0x02, 0x05, 0x05}, rice}))), CodecStatus::BadMask);
    }
    // Header numbers: the brick as two bytes (0x80 0x00) is not its shortest form; cut off it is truncated.
    ASSERT_LT(data.size(), 128u);
    std::vector<uint8_t> overlong = {0x80, 0x00, 0x02, 0x02, static_cast<uint8_t>(data.size()), 0, 0, 0, 0};
    const uint32_t crc = crc32c(data.data(), data.size(), crc32c(overlong.data(), 5));
    for (int k = 0; k < 4; ++k) overlong[5 + k] = static_cast<uint8_t>(crc >> (8 * k));
    overlong.insert(overlong.end(), data.begin(), data.end());
    std::vector<uint8_t> f;
    const std::span<const uint8_t> sections[] = {overlong};
    writeFrame(layout, 2, sections, f);
    StreamDecoder other(layout);
    EXPECT_EQ(other.apply(f.data(), f.size()), CodecStatus::NonCanonical);
    const uint8_t cut[] = {0x80};
    SectionInfo info;
    EXPECT_EQ(readSection(layout, cut, 1, &info), CodecStatus::Truncated);
  }
}

// A compressed section holds exactly one zstd frame (format 3 without its 4-byte magic): the same
// payload with an empty frame after it is one more spelling, refused by the container check and
// the decoder alike.
TEST(Stream, Format3ZstdDataIsOneFrameWithoutItsMagic) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::L2);
  std::vector<float> probes(64 * kProbeFloats, 0.0f);
  for (int p = 0; p < 64; ++p)
    for (int c = 0; c < 3; ++c) probes[p * kProbeFloats + c] = 1.0f;  // alike: zstd finds the repeats
  StreamEncoder enc(layout);
  enc.update(probes.data(), nullptr);
  std::vector<uint8_t> key;
  enc.writeKeyframeFrame(key);
  SectionBytes b;
  ASSERT_TRUE(locateSection(key.data() + kFrameHeaderSize, key.size() - kFrameHeaderSize, &b));
  const uint8_t kind = key[kFrameHeaderSize + b.kindAt];
  ASSERT_EQ(kind, 0x05) << "a compressed keyframe";
  const std::vector<uint8_t> data(key.begin() + kFrameHeaderSize + b.dataAt, key.end());
  EXPECT_NE(data[0], 0x28) << "the magic is left out";
  const auto decoded = [&](const std::vector<uint8_t>& section) {
    std::vector<uint8_t> f;
    const std::span<const uint8_t> sections[] = {section};
    writeFrame(layout, 1, sections, f);
    StreamDecoder dec(layout);
    const CodecStatus checked = verifyFrame(f.data(), f.size());
    const CodecStatus applied = dec.apply(f.data(), f.size());
    EXPECT_EQ(checked, applied);
    return applied;
  };
  ASSERT_EQ(decoded(sealSection(0, 1, kind, data)), CodecStatus::Ok);
  std::vector<uint8_t> twoFrames = data;
  const uint8_t emptyFrame[] = {0x28, 0xb5, 0x2f, 0xfd, 0x20, 0x00, 0x01, 0x00, 0x00};  // zstd of nothing
  twoFrames.insert(twoFrames.end(), std::begin(emptyFrame), std::end(emptyFrame));
  EXPECT_EQ(decoded(sealSection(0, 1, kind, twoFrames)), CodecStatus::DecompressFailed);
  std::vector<uint8_t> withMagic = {0x28, 0xb5, 0x2f, 0xfd};
  withMagic.insert(withMagic.end(), data.begin(), data.end());
  EXPECT_EQ(decoded(sealSection(0, 1, kind, withMagic)), CodecStatus::DecompressFailed);
}

// An 8×4×4 l2 stream in two bricks: brick 0 under a uniform sky (L1 is exact there), brick 1 lit
// by three small lights each (it needs the whole L2 band: one light alone is zonal, which zh3
// holds). With an error bound each brick goes in the cheapest representation that keeps its probes
// within it, in one stream one decoder reads; when brick 0's light changes it moves up, its version
// a keyframe in the new representation.
std::vector<float> twoKindsOfLight(std::mt19937& rng, bool litBrick0, float sky = 1.0f) {
  std::vector<float> p(128 * kProbeFloats, 0.0f);
  for (int i = 0; i < 128; ++i) {
    const bool brick0 = (i % 8) < 4;  // x < 4
    test::Probe q{};
    if (brick0 && !litBrick0) {
      for (int c = 0; c < 3; ++c) q[c] = 3.5449077f * sky * (0.5f + 0.1f * static_cast<float>(c));  // constant radiance
    } else {
      q = test::randomNonNegativeProbe(rng, 3, 0.02f);  // three lights: not zonal, so not zh3 either
    }
    std::copy(q.begin(), q.end(), p.begin() + i * kProbeFloats);
  }
  return p;
}

// Sections stored raw (readable in a test), per-brick representation within `bound` (0: off).
EncoderOptions rawSections(float bound) {
  EncoderOptions options;
  options.errorBound = bound;
  options.compress = false;
  return options;
}

TEST(Stream, PerBrickRepresentationMeetsTheBoundInTheCheapestOne) {
  const StreamLayout layout = makeLayout(8, 4, 4, Representation::L2);
  std::mt19937 rng(31);
  const std::vector<float> frame0 = twoKindsOfLight(rng, false);
  StreamEncoder bounded(layout, rawSections(0.05f)), full(layout, rawSections(0.0f));
  bounded.update(frame0.data(), nullptr);
  full.update(frame0.data(), nullptr);
  EXPECT_EQ(bounded.brickRepresentation(0), Representation::L1);
  EXPECT_EQ(bounded.brickRepresentation(1), Representation::L2);
  std::vector<uint8_t> a, b;
  bounded.writeKeyframeFrame(a);
  full.writeKeyframeFrame(b);
  EXPECT_LT(a.size(), b.size() - 64 * (28 - 13) + 64);  // brick 0's 64 records at 13 B instead of 28
  StreamDecoder dec(layout);
  ASSERT_EQ(dec.apply(a.data(), a.size()), CodecStatus::Ok);
  expectSameState(bounded, dec, "keyframes");
  for (int brick = 0; brick < 2; ++brick) {  // each brick within the bound over its probes
    double err = 0, energy = 0;
    for (int i = 0; i < 128; ++i)
      if ((i % 8) / 4 == brick)
        irradianceErrorEnergy(dec.probes() + i * kProbeFloats, frame0.data() + i * kProbeFloats, err, energy);
    EXPECT_LE(std::sqrt(err / energy), 0.05) << "brick " << brick;
  }
  // Brick 0's light changes: it needs more than L1 now, and its new version is a keyframe.
  const std::vector<float> frame1 = twoKindsOfLight(rng, true);
  bounded.update(frame1.data(), nullptr);
  EXPECT_NE(bounded.brickRepresentation(0), Representation::L1);
  EXPECT_TRUE(bounded.deltaIsKeyframe(0));
  bounded.writeChangedFrame(a);
  ASSERT_EQ(dec.apply(a.data(), a.size()), CodecStatus::Ok);
  expectSameState(bounded, dec, "after the switch");
  // Without a bound the same stream never changes representation.
  full.update(frame1.data(), nullptr);
  EXPECT_EQ(full.brickRepresentation(0), Representation::L2);
  EXPECT_FALSE(full.deltaIsKeyframe(0));
}

// A section's representation is one of the stream's cheaper ones, never its own spelled out, and a
// delta must be in the representation its brick holds.
TEST(Stream, SectionRepresentationsOutsideTheStreamsAreRefused) {
  const StreamLayout layout = makeLayout(8, 4, 4, Representation::L2);
  std::mt19937 rng(32);
  const std::vector<float> frame0 = twoKindsOfLight(rng, false);
  StreamEncoder enc(layout, rawSections(0.05f));
  enc.update(frame0.data(), nullptr);
  std::vector<uint8_t> key;
  enc.writeKeyframeFrame(key);
  // Brick 0's section comes first: its kind byte says keyframe (1) in l1 (1 << 4).
  SectionBytes first;
  ASSERT_TRUE(locateSection(key.data() + kFrameHeaderSize, key.size() - kFrameHeaderSize, &first));
  const size_t kindAt = kFrameHeaderSize + first.kindAt;
  ASSERT_EQ(key[kindAt], 0x11);
  const auto refused = [&](uint8_t kind) {
    std::vector<uint8_t> f = key;
    f[kindAt] = kind;
    rewriteFrameChecksums(f);
    StreamDecoder dec(layout);
    return dec.apply(f.data(), f.size());
  };
  EXPECT_EQ(refused(0x41), CodecStatus::BadSectionKind);  // l2 spelled out in an l2 stream
  EXPECT_EQ(refused(0x51), CodecStatus::BadSectionKind);  // fp16: not a brick representation
  EXPECT_EQ(refused(0x21), CodecStatus::BadSectionKind);  // zh3h: not a brick representation
  EXPECT_EQ(refused(0xf1), CodecStatus::BadSectionKind);
  // A delta in l1 for a brick the decoder holds in l2 (as a format 1 stream or no bound would).
  StreamEncoder plain(layout, rawSections(0.0f));
  plain.update(frame0.data(), nullptr);
  std::vector<uint8_t> plainKey;
  plain.writeKeyframeFrame(plainKey);
  StreamDecoder dec(layout);
  ASSERT_EQ(dec.apply(plainKey.data(), plainKey.size()), CodecStatus::Ok);
  enc.update(twoKindsOfLight(rng, false, 1.5f).data(), nullptr);  // brick 0 brighter, still l1: an l1 delta
  ASSERT_EQ(enc.brickRepresentation(0), Representation::L1);
  ASSERT_FALSE(enc.deltaIsKeyframe(0));
  std::vector<uint8_t> delta;
  enc.writeChangedFrame(delta);
  EXPECT_EQ(dec.apply(delta.data(), delta.size()), CodecStatus::BadSectionKind);
}

TEST(Stream, InactiveProbesAreNeverEncoded) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::L2);
  std::mt19937 rng(3);
  std::vector<float> a = test::movingLightFrame(64, 0, 0.0f, rng);
  std::vector<float> b = a;
  std::vector<uint8_t> active(64, 1);
  for (int p = 0; p < 64; p += 3) {
    active[p] = 0;
    for (int i = 0; i < kProbeFloats; ++i) {
      a[p * kProbeFloats + i] = std::nanf("");
      b[p * kProbeFloats + i] = 1e30f * static_cast<float>(i);
    }
  }
  StreamEncoder ea(layout), eb(layout);
  ea.update(a.data(), active.data());
  eb.update(b.data(), active.data());
  std::vector<uint8_t> fa, fb;
  ea.writeKeyframeFrame(fa);
  eb.writeKeyframeFrame(fb);
  EXPECT_EQ(fa, fb);
  StreamDecoder dec(layout);
  ASSERT_EQ(dec.apply(fa.data(), fa.size()), CodecStatus::Ok);
  for (int p = 0; p < 64; p += 3) {
    EXPECT_EQ(dec.activeMask()[p], 0);
    for (int i = 0; i < kProbeFloats; ++i) EXPECT_EQ(dec.probes()[p * kProbeFloats + i], 0.0f);
  }
}

TEST(Stream, UnchangedFrameMakesNoVersions) {
  const StreamLayout layout = makeLayout(5, 5, 5, Representation::Zh3);
  std::mt19937 rng(5);
  const std::vector<float> probes = test::movingLightFrame(125, 3, 0.02f, rng);
  StreamEncoder enc(layout);
  EXPECT_EQ(enc.update(probes.data(), nullptr), brickCount(layout));
  EXPECT_EQ(enc.update(probes.data(), nullptr), 0u);
  std::vector<uint8_t> frame;
  enc.writeChangedFrame(frame);
  EXPECT_EQ(frame.size(), kFrameHeaderSize);
}

TEST(Stream, DeadzoneSavesBytesWithBoundedError) {
  const StreamLayout layout = makeLayout(8, 4, 8, Representation::L2);
  size_t bytes[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    EncoderOptions options;
    options.deadzone = k == 0 ? 0 : 3;
    StreamEncoder enc(layout, options);
    std::mt19937 rng(77);
    std::vector<uint8_t> frame;
    for (int f = 0; f < 60; ++f) {
      const std::vector<float> probes = test::movingLightFrame(256, f, 0.01f, rng);
      enc.update(probes.data(), nullptr);
      enc.writeChangedFrame(frame);
      if (f > 0) bytes[k] += frame.size();
    }
  }
  // Format 4 spells small differences in a few bits each (Rice codes), so the dead-zone saves
  // about 11 % here where byte planes made it more than 25 %.
  EXPECT_LT(bytes[1], bytes[0] * 19 / 20) << bytes[0] << " vs " << bytes[1];
}

TEST(Stream, SectionForPicksDeltaOrKeyframe) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::L1);
  StreamEncoder enc(layout);
  StreamDecoder dec(layout);
  std::mt19937 rng(8);
  std::vector<uint8_t> frame;
  for (int f = 0; f < 3; ++f) enc.update(test::movingLightFrame(64, f * 10, 0.0f, rng).data(), nullptr);
  ASSERT_EQ(enc.brickVersion(0), 3u);
  EXPECT_TRUE(enc.sectionFor(0, 3).empty());
  EXPECT_EQ(enc.sectionFor(0, 2).data(), enc.deltaSection(0).data());
  const std::span<const uint8_t> key = enc.sectionFor(0, 0);
  const std::span<const uint8_t> sections[] = {key};
  writeFrame(layout, enc.frameSequence(), sections, frame);
  ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
  expectSameState(enc, dec, "after keyframe");
}

TEST(Stream, ChangeSinceAccumulatesOverVersions) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::L2);
  StreamEncoder enc(layout);
  std::mt19937 rng(4);
  for (int f = 0; f < 4; ++f) enc.update(test::movingLightFrame(64, f * 10, 0.0f, rng).data(), nullptr);
  ASSERT_EQ(enc.brickVersion(0), 4u);
  EXPECT_EQ(enc.changeSince(0, 4), 0.0f);
  EXPECT_EQ(enc.changeSince(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(enc.changeSince(0, 3), enc.brickChange(0));
  EXPECT_GT(enc.changeSince(0, 1), enc.changeSince(0, 2));
  EXPECT_GT(enc.changeSince(0, 2), enc.changeSince(0, 3));
  EXPECT_GT(enc.brickChange(0), 0.0f);
}

TEST(Stream, DeltaAgainstMissingBaseIsRejectedAndStateKept) {
  const StreamLayout layout = makeLayout(4, 4, 8, Representation::L1);
  StreamEncoder enc(layout);
  StreamDecoder dec(layout);
  std::mt19937 rng(9);
  std::vector<uint8_t> frame;
  enc.update(test::movingLightFrame(128, 0, 0.0f, rng).data(), nullptr);
  enc.writeChangedFrame(frame);
  ASSERT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::Ok);
  enc.update(test::movingLightFrame(128, 20, 0.0f, rng).data(), nullptr);
  enc.update(test::movingLightFrame(128, 40, 0.0f, rng).data(), nullptr);  // decoder misses version 2
  enc.writeChangedFrame(frame);
  const std::vector<float> before(dec.probes(), dec.probes() + 128 * kProbeFloats);
  EXPECT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::BaseVersionMismatch);
  EXPECT_EQ(0, std::memcmp(before.data(), dec.probes(), before.size() * sizeof(float)));
  EXPECT_EQ(dec.brickVersion(0), 1u);
}

TEST(Stream, FrameIsAllOrNothing) {
  // Two bricks; the second section is a delta the decoder cannot apply: the first brick must not
  // change either.
  const StreamLayout layout = makeLayout(4, 4, 8, Representation::L2);
  StreamEncoder enc(layout);
  StreamDecoder dec(layout);
  std::mt19937 rng(10);
  enc.update(test::movingLightFrame(128, 0, 0.0f, rng).data(), nullptr);
  const std::vector<uint8_t> key0(enc.keyframeSection(0).begin(), enc.keyframeSection(0).end());
  enc.update(test::movingLightFrame(128, 30, 0.0f, rng).data(), nullptr);
  const std::span<const uint8_t> sections[] = {key0, enc.deltaSection(1)};  // brick 1 base not held
  std::vector<uint8_t> frame;
  writeFrame(layout, 2, sections, frame);
  EXPECT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::BaseVersionMismatch);
  EXPECT_EQ(dec.brickVersion(0), 0u);
  EXPECT_EQ(dec.activeMask()[0], 0);
}

TEST(Stream, RejectsLayoutMismatchAndDuplicates) {
  const StreamLayout layout = makeLayout(4, 4, 4, Representation::L1);
  StreamEncoder enc(layout);
  std::mt19937 rng(12);
  enc.update(test::movingLightFrame(64, 0, 0.0f, rng).data(), nullptr);
  std::vector<uint8_t> frame;
  enc.writeKeyframeFrame(frame);
  StreamDecoder other(makeLayout(4, 4, 4, Representation::L2));
  EXPECT_EQ(other.apply(frame.data(), frame.size()), CodecStatus::LayoutMismatch);
  const std::span<const uint8_t> twice[] = {enc.keyframeSection(0), enc.keyframeSection(0)};
  writeFrame(makeLayout(4, 4, 8, Representation::L1), 1, twice, frame);
  StreamDecoder dec(makeLayout(4, 4, 8, Representation::L1));
  EXPECT_EQ(dec.apply(frame.data(), frame.size()), CodecStatus::DuplicateBrick);
}

}  // namespace
}  // namespace probecast

#include "probecast/codec/probe_file.h"

namespace probecast {
namespace {

TEST(ProbeFile, RoundTripAndRejections) {
  ProbeVolume v;
  v.grid.dims[0] = 3;
  v.grid.dims[1] = 2;
  v.grid.dims[2] = 1;
  v.grid.bounds.min[0] = -1;
  v.grid.bounds.max[0] = 1;
  v.updates = 4;
  v.samplesPerProbe = 128;
  v.probes.resize(6 * 27);
  for (size_t i = 0; i < v.probes.size(); ++i) v.probes[i] = 0.1f * static_cast<float>(i);
  v.active = {1, 1, 0, 1, 1, 1};
  std::vector<uint8_t> bytes;
  serializeProbeVolume(v, bytes);
  ProbeVolume back;
  std::string error;
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_EQ(back.probes, v.probes);
  EXPECT_EQ(back.active, v.active);
  EXPECT_EQ(back.samplesPerProbe, 128u);
  // Every truncation and every single-byte corruption is rejected with a reason.
  for (size_t len = 0; len < bytes.size(); ++len) {
    EXPECT_FALSE(parseProbeVolume(bytes.data(), len, back, error)) << len;
    EXPECT_FALSE(error.empty());
  }
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<uint8_t> bad = bytes;
    bad[i] ^= 0x20;
    EXPECT_FALSE(parseProbeVolume(bad.data(), bad.size(), back, error)) << i;
  }
  // NaN radiance is refused even with a valid checksum.
  v.probes[5] = std::nanf("");
  serializeProbeVolume(v, bytes);
  EXPECT_FALSE(parseProbeVolume(bytes.data(), bytes.size(), back, error));
  EXPECT_NE(error.find("NaN"), std::string::npos);
}

TEST(ProbeFile, OffsetsRoundTripAndVersion1FilesAreStillRead) {
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 2, 1}, {{-1, 0, 0}, {1, 1, 0}}});  // cells 1 m (x), 1 m (y)
  for (size_t i = 0; i < v.probes.size(); ++i) v.probes[i] = 0.01f * static_cast<float>(i);
  v.offsets.assign(6 * 3, 0.0f);
  v.offsets[3 * 4 + 0] = 0.45f;   // probe 4: 0.45 m along x
  v.offsets[3 * 4 + 1] = -0.125f;
  std::vector<uint8_t> bytes;
  serializeProbeVolume(v, bytes);
  ProbeVolume back;
  std::string error;
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_EQ(back.offsets, v.offsets);  // floats, bit for bit
  for (size_t len = 0; len < bytes.size(); ++len) EXPECT_FALSE(parseProbeVolume(bytes.data(), len, back, error)) << len;

  // A version 1 file, as written before offsets existed (no offset count): read, no offsets.
  ProbeVolume old = v;
  old.offsets.clear();
  serializeProbeVolume(old, bytes);
  bytes.erase(bytes.end() - 60, bytes.end() - 4);  // the zero offset count, the rule and the (unknown) scene
  bytes[4] = 1;
  bytes.resize(bytes.size() - 4);
  const uint32_t crc = crc32c(bytes.data(), bytes.size());
  for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(crc >> (8 * i)));
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_TRUE(back.offsets.empty());
  EXPECT_EQ(back.probes, v.probes);

  // Offsets beyond half a cell, NaN, or on an axis of one probe are refused under a valid checksum.
  const auto refusedWith = [&](size_t at, float value, const std::string& why) {
    ProbeVolume bad = v;
    bad.offsets[at] = value;
    serializeProbeVolume(bad, bytes);
    EXPECT_FALSE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << at;
    EXPECT_NE(error.find(why), std::string::npos) << error;
  };
  refusedWith(3 * 2, 0.51f, "more than half its cell");
  refusedWith(3 * 2 + 1, std::nanf(""), "non-finite");
  refusedWith(3 * 5 + 2, 0.01f, "more than half its cell (0");  // z has one probe
}

// Bytes of `v` (no scene) as a file of `version` (3: without the scene, 2: without the rule
// either), checksum renewed.
std::vector<uint8_t> probeFileAs(const ProbeVolume& v, uint8_t version) {
  std::vector<uint8_t> bytes;
  serializeProbeVolume(v, bytes);
  bytes.resize(bytes.size() - 4);
  if (version <= 3) bytes.resize(bytes.size() - 44);
  if (version == 2) bytes.resize(bytes.size() - 8);
  bytes[4] = version;
  const uint32_t crc = crc32c(bytes.data(), bytes.size());
  for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(crc >> (8 * i)));
  return bytes;
}

TEST(ProbeFile, AreaLightRuleRoundTripsOldFilesReadAsOffAndABadRuleIsRefused) {
  ProbeVolume v = makeProbeVolume(ProbeGrid{{2, 2, 1}, {{0, 0, 0}, {1, 1, 0}}});
  v.areaLights = {kAreaLightRuleVersion, 0.125f};
  std::vector<uint8_t> bytes;
  serializeProbeVolume(v, bytes);
  ProbeVolume back;
  std::string error;
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_EQ(back.areaLights, v.areaLights);
  for (size_t len = 0; len < bytes.size(); ++len) EXPECT_FALSE(parseProbeVolume(bytes.data(), len, back, error)) << len;

  // A version 2 file (before the rule) holds every emitter: read with the rule off.
  bytes = probeFileAs(v, 2);
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_FALSE(back.areaLights.on());

  // An unknown rule version, a threshold outside [0, 1] or NaN, or a threshold with the rule off
  // are refused under a valid checksum.
  const auto refusedWith = [&](AreaLightRule rule, const std::string& why) {
    ProbeVolume bad = v;
    bad.areaLights = rule;
    bytes = probeFileAs(bad, 3);
    EXPECT_FALSE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << rule.version;
    EXPECT_NE(error.find(why), std::string::npos) << error;
  };
  refusedWith({2, 0.05f}, "rule version 2 is unknown");
  refusedWith({1, 1.5f}, "threshold is not a power share");
  refusedWith({1, std::nanf("")}, "threshold is not a power share");
  refusedWith({0, 0.05f}, "off but a threshold");
}

TEST(ProbeFile, SceneRoundTripsVersion3FilesReadAsUnknownAndBadScenesAreRefused) {
  ProbeVolume v = makeProbeVolume(ProbeGrid{{2, 2, 1}, {{0, 0, 0}, {1, 1, 0}}});
  v.scene.manifest = R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})";
  for (size_t i = 0; i < v.scene.hash.size(); ++i) v.scene.hash[i] = static_cast<uint8_t>(i * 7 + 1);
  v.scene.time = 0.4375;
  std::vector<uint8_t> bytes;
  serializeProbeVolume(v, bytes);
  ProbeVolume back;
  std::string error;
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_EQ(back.scene, v.scene);
  for (size_t len = 0; len < bytes.size(); ++len) EXPECT_FALSE(parseProbeVolume(bytes.data(), len, back, error)) << len;

  // A version 3 file (before scenes were named): read, its scene unknown.
  ProbeVolume unnamed = v;
  unnamed.scene = {};
  bytes = probeFileAs(unnamed, 3);
  ASSERT_TRUE(parseProbeVolume(bytes.data(), bytes.size(), back, error)) << error;
  EXPECT_FALSE(back.scene.known());

  // A non-finite time, or a hash without a manifest, under a valid checksum.
  const auto refusedWith = [&](const SceneStamp& scene, const std::string& why) {
    ProbeVolume bad = v;
    bad.scene = scene;
    serializeProbeVolume(bad, bytes);
    EXPECT_FALSE(parseProbeVolume(bytes.data(), bytes.size(), back, error));
    EXPECT_NE(error.find(why), std::string::npos) << error;
  };
  SceneStamp nan = v.scene;
  nan.time = std::nan("");
  refusedWith(nan, "scene time is not finite");
  SceneStamp hashOnly = v.scene;
  hashOnly.manifest.clear();
  refusedWith(hashOnly, "scene hash without its manifest");
}

}  // namespace
}  // namespace probecast
