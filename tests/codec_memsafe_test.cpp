// Every truncation and single-byte corruption of valid frames is rejected with an error code and
// leaves the decoder unchanged; payload corruptions with repaired checksums never read or write
// out of bounds (run under AddressSanitizer by .ci/run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/stream.h"
#include "test_probes.h"

namespace probecast {
namespace {

struct Streams {
  StreamLayout layout;
  std::vector<uint8_t> keyframe;  // takes a new decoder to version state A
  std::vector<uint8_t> delta;     // takes state A to B
};

Streams makeStreams(Representation repr) {
  Streams s;
  s.layout.grid[0] = 5;
  s.layout.grid[1] = 3;
  s.layout.grid[2] = 4;
  s.layout.brickDim = 4;
  s.layout.repr = repr;
  StreamEncoder enc(s.layout);
  std::mt19937 rng(42);
  std::vector<uint8_t> active(60, 1);
  active[7] = 0;
  enc.update(test::movingLightFrame(60, 0, 0.02f, rng).data(), active.data());
  enc.writeKeyframeFrame(s.keyframe);
  active[9] = 0;
  active[7] = 1;
  enc.update(test::movingLightFrame(60, 8, 0.02f, rng).data(), active.data());
  enc.writeChangedFrame(s.delta);
  return s;
}

std::vector<float> snapshot(const StreamDecoder& d) {
  const size_t n = probeCount(d.layout()) * kProbeFloats;
  return {d.probes(), d.probes() + n};
}

bool allFinite(const StreamDecoder& d) {
  for (float v : snapshot(d))
    if (!std::isfinite(v)) return false;
  return true;
}

// Recomputes the header and section CRCs so corruption reaches the payload parsers.
void repairChecksums(std::vector<uint8_t>& f) { rewriteFrameChecksums(f); }

class MemorySafety : public ::testing::TestWithParam<Representation> {};

TEST_P(MemorySafety, EveryTruncationIsRejected) {
  const Streams s = makeStreams(GetParam());
  for (const std::vector<uint8_t>* frame : {&s.keyframe, &s.delta}) {
    StreamDecoder dec(s.layout);
    if (frame == &s.delta) {
      ASSERT_EQ(dec.apply(s.keyframe.data(), s.keyframe.size()), CodecStatus::Ok);
    }
    const std::vector<float> before = snapshot(dec);
    for (size_t len = 0; len < frame->size(); ++len) {
      std::vector<uint8_t> cut(frame->begin(), frame->begin() + static_cast<std::ptrdiff_t>(len));  // exact size: ASan sees overreads
      ASSERT_NE(dec.apply(cut.data(), cut.size()), CodecStatus::Ok) << "length " << len;
      ASSERT_NE(verifyFrame(cut.data(), cut.size()), CodecStatus::Ok) << "length " << len;
    }
    EXPECT_EQ(before, snapshot(dec));
    ASSERT_EQ(dec.apply(frame->data(), frame->size()), CodecStatus::Ok);
  }
}

TEST_P(MemorySafety, EverySingleByteCorruptionIsRejected) {
  // CRC-32C detects every error burst up to 32 bits, so no single-byte change may pass.
  const Streams s = makeStreams(GetParam());
  StreamDecoder dec(s.layout);
  ASSERT_EQ(dec.apply(s.keyframe.data(), s.keyframe.size()), CodecStatus::Ok);
  const std::vector<float> before = snapshot(dec);
  for (size_t i = 0; i < s.delta.size(); ++i) {
    for (int x : {0x01, 0x80, 0xff}) {
      std::vector<uint8_t> bad = s.delta;
      bad[i] = static_cast<uint8_t>(bad[i] ^ x);
      ASSERT_NE(dec.apply(bad.data(), bad.size()), CodecStatus::Ok) << "byte " << i << " xor " << x;
      ASSERT_NE(verifyFrame(bad.data(), bad.size()), CodecStatus::Ok) << "byte " << i << " xor " << x;
    }
  }
  EXPECT_EQ(before, snapshot(dec));
}

TEST_P(MemorySafety, CorruptionWithRepairedChecksumsIsSafe) {
  // Past the CRCs, every parser sees garbage: it must answer an error code or a valid state.
  const Streams s = makeStreams(GetParam());
  std::mt19937 rng(7);
  int rejected = 0;
  for (const std::vector<uint8_t>* frame : {&s.keyframe, &s.delta}) {
    for (size_t i = 0; i < frame->size(); ++i) {
      for (int x : {0x01, 0x10, 0xff}) {
        StreamDecoder dec(s.layout);
        if (frame == &s.delta) {
      ASSERT_EQ(dec.apply(s.keyframe.data(), s.keyframe.size()), CodecStatus::Ok);
    }
        const std::vector<float> before = snapshot(dec);
        std::vector<uint8_t> bad = *frame;
        bad[i] = static_cast<uint8_t>(bad[i] ^ x);
        repairChecksums(bad);
        const CodecStatus st = dec.apply(bad.data(), bad.size());
        // What decodes has an intact container: verifyFrame never refuses a frame apply took.
        if (st == CodecStatus::Ok) {
          ASSERT_EQ(verifyFrame(bad.data(), bad.size()), CodecStatus::Ok) << "byte " << i;
        }
        if (st != CodecStatus::Ok) {
          ++rejected;
          ASSERT_EQ(before, snapshot(dec)) << "failed apply changed state at byte " << i;
        }
        ASSERT_TRUE(allFinite(dec)) << "byte " << i;
      }
    }
  }
  EXPECT_GT(rejected, 0);
}

TEST(MemorySafety, TrailingBytesAndWrongVersionAreRejected) {
  const Streams s = makeStreams(Representation::L2);
  StreamDecoder dec(s.layout);
  std::vector<uint8_t> longer = s.keyframe;
  longer.push_back(0);
  EXPECT_EQ(dec.apply(longer.data(), longer.size()), CodecStatus::TrailingBytes);
  for (uint8_t version : {uint8_t{0}, static_cast<uint8_t>(kFormatVersion + 1)}) {
    std::vector<uint8_t> other = s.keyframe;
    other[4] = version;
    repairChecksums(other);
    EXPECT_EQ(dec.apply(other.data(), other.size()), CodecStatus::UnsupportedVersion) << int(version);
  }
  std::vector<uint8_t> magic = s.keyframe;
  magic[0] = 'X';
  EXPECT_EQ(dec.apply(magic.data(), magic.size()), CodecStatus::BadMagic);
  std::vector<uint8_t> count = s.keyframe;
  count[20] = 200;  // more sections than bricks
  repairChecksums(count);
  EXPECT_EQ(dec.apply(count.data(), count.size()), CodecStatus::BadBrickIndex);
  EXPECT_EQ(dec.apply(nullptr, 0), CodecStatus::Truncated);
}

TEST_P(MemorySafety, VerifyFrameChecksTheContainerWithoutDecoding) {
  const Streams s = makeStreams(GetParam());
  FrameHeader h;
  ASSERT_EQ(verifyFrame(s.keyframe.data(), s.keyframe.size(), &h), CodecStatus::Ok);
  EXPECT_EQ(h.layout.grid[0], 5);
  EXPECT_EQ(h.layout.repr, GetParam());
  EXPECT_GT(h.sectionCount, 0u);
  // A delta checks out on its own: verifyFrame holds no brick versions, the decoder does.
  ASSERT_EQ(verifyFrame(s.delta.data(), s.delta.size()), CodecStatus::Ok);
  StreamDecoder fresh(s.layout);
  EXPECT_EQ(fresh.apply(s.delta.data(), s.delta.size()), CodecStatus::BaseVersionMismatch);
  std::vector<uint8_t> longer = s.delta;
  longer.push_back(0);
  EXPECT_EQ(verifyFrame(longer.data(), longer.size()), CodecStatus::TrailingBytes);
  // The last byte of the first section's data: only that section's CRC can tell.
  std::vector<uint8_t> bad = s.keyframe;
  SectionBytes first;
  ASSERT_TRUE(locateSection(bad.data() + kFrameHeaderSize, bad.size() - kFrameHeaderSize, &first));
  const size_t firstEnd = kFrameHeaderSize + first.dataAt + first.storedSize;
  ASSERT_LE(firstEnd, bad.size());
  bad[firstEnd - 1] = static_cast<uint8_t>(bad[firstEnd - 1] ^ 0x20);
  EXPECT_EQ(verifyFrame(bad.data(), bad.size()), CodecStatus::SectionChecksum);
  bad = s.keyframe;
  bad[17] = static_cast<uint8_t>(bad[17] ^ 1);  // frame sequence, under the header CRC
  EXPECT_EQ(verifyFrame(bad.data(), bad.size()), CodecStatus::HeaderChecksum);
  EXPECT_EQ(verifyFrame(nullptr, 0), CodecStatus::Truncated);
}

INSTANTIATE_TEST_SUITE_P(AllRepresentations, MemorySafety, ::testing::ValuesIn(kAllRepresentations),
                         [](const auto& p) { return std::string(representationName(p.param)); });

}  // namespace
}  // namespace probecast
