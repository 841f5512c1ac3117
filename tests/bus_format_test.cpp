// The probe bus format: golden bytes, round trips, and refusal of every malformed message with a
// reason (truncations, corruptions, lying sizes, sections that are not what the message says).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "probecast/codec/crc32c.h"
#include "probecast/service/bus_format.h"
#include "test_probes.h"

namespace probecast::bus {
namespace {

Volume sampleVolume() {
  Volume v;
  v.epoch = 0x0102030405060708ull;
  v.publishedUs = 0x1122334455667788ull;
  v.layout.grid[0] = 16;
  v.layout.grid[1] = 4;
  v.layout.grid[2] = 16;
  v.layout.brickDim = 4;
  v.layout.repr = Representation::Zh3;
  v.bounds = {{-2.0f, 0.0f, -2.0f}, {1.5f, 1.5f, 5.5f}};
  return v;
}

// Two versions of every brick of the sample volume's grid; messages of the second (keyframe + delta).
struct Encoded {
  StreamEncoder encoder{sampleVolume().layout};
  std::vector<std::vector<uint8_t>> keyframes;  // copies: the encoder's spans move on
  Encoded() {
    std::mt19937 rng(3);
    encoder.update(test::movingLightFrame(1024, 0, 0.01f, rng).data(), nullptr);
    encoder.update(test::movingLightFrame(1024, 1, 0.01f, rng).data(), nullptr);
    for (uint32_t b = 0; b < brickCount(encoder.layout()); ++b) {
      const auto k = encoder.keyframeSection(b);
      keyframes.emplace_back(k.begin(), k.end());
    }
  }
  std::vector<uint8_t> message(uint32_t b, bool withDelta = true) {
    Brick brick;
    brick.brick = b;
    brick.version = encoder.brickVersion(b);
    brick.producerFrame = 2;
    brick.change = encoder.brickChange(b);
    brick.keyframe = keyframes[b];
    if (withDelta) brick.delta = encoder.deltaSection(b);
    std::vector<uint8_t> out;
    writeBrickMessage(sampleVolume(), brick, kEndOfBatch, out);
    return out;
  }
};

std::string refusal(const std::vector<uint8_t>& bytes) {
  Message m;
  std::string why;
  if (readMessage(bytes.data(), bytes.size(), m, why)) return "";
  EXPECT_FALSE(why.empty());
  return why;
}

// Recomputes the header checksum so a test reaches the checks behind it.
void reseal(std::vector<uint8_t>& m) {
  uint32_t crc = crc32c(m.data(), 12);
  crc = crc32c(m.data() + kHeaderSize, m.size() - kHeaderSize, crc);
  std::memcpy(m.data() + 12, &crc, 4);
}

TEST(BusFormat, VolumeMessageGoldenBytes) {
  // Written out by hand from the format in bus_format.h; the CRC-32C is of bytes 0-11 and 16-67,
  // computed independently.
  const uint8_t golden[] = {
      0x50, 0x43, 0x42, 0x4d, 0x01, 0x01, 0x01, 0x00, 0x34, 0x00, 0x00, 0x00, 0x08, 0xaa, 0x49, 0xd9,  // header
      0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11,  // epoch, time
      0x01, 0x03, 0x04, 0x00, 0x10, 0x00, 0x04, 0x00, 0x10, 0x00, 0x00, 0x00,                          // layout
      0x00, 0x00, 0x00, 0xc0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xc0,                          // min
      0x00, 0x00, 0xc0, 0x3f, 0x00, 0x00, 0xc0, 0x3f, 0x00, 0x00, 0xb0, 0x40};                         // max
  std::vector<uint8_t> out;
  writeVolumeMessage(sampleVolume(), kEndOfBatch, out);
  EXPECT_EQ(out, std::vector<uint8_t>(std::begin(golden), std::end(golden)));
  Message m;
  std::string why;
  ASSERT_TRUE(readMessage(golden, sizeof golden, m, why)) << why;
  EXPECT_EQ(m.kind, Kind::Volume);
  EXPECT_EQ(m.flags, kEndOfBatch);
  EXPECT_EQ(m.volume.epoch, 0x0102030405060708ull);
  EXPECT_EQ(m.volume.publishedUs, 0x1122334455667788ull);
  EXPECT_EQ(m.volume.layout.grid[2], 16);
  EXPECT_EQ(m.volume.layout.repr, Representation::Zh3);
  EXPECT_EQ(m.volume.bounds.max[2], 5.5f);
}

TEST(BusFormat, BrickMessageRoundTripsAndItsSectionsDecode) {
  Encoded e;
  const std::vector<uint8_t> bytes = e.message(5);
  Message m;
  std::string why;
  ASSERT_TRUE(readMessage(bytes.data(), bytes.size(), m, why)) << why;
  ASSERT_EQ(m.kind, Kind::Brick);
  EXPECT_EQ(m.brick.brick, 5u);
  EXPECT_EQ(m.brick.version, 2u);
  EXPECT_EQ(m.brick.producerFrame, 2u);
  EXPECT_EQ(m.brick.change, e.encoder.brickChange(5));
  // A decoder fed the first version's keyframe and then the message's delta ends where one fed
  // the message's keyframe alone does.
  std::vector<uint8_t> again;
  writeBrickMessage(m.volume, m.brick, m.flags, again);
  EXPECT_EQ(again, bytes);
  StreamDecoder viaKey(m.volume.layout);
  std::vector<uint8_t> frame;
  const std::span<const uint8_t> key[] = {m.brick.keyframe};
  writeFrame(m.volume.layout, 1, key, frame);
  ASSERT_EQ(viaKey.apply(frame.data(), frame.size()), CodecStatus::Ok);
  EXPECT_EQ(viaKey.brickVersion(5), 2u);
  EXPECT_FALSE(m.brick.delta.empty());
  // Without a delta the message is shorter and still valid.
  const std::vector<uint8_t> keyOnly = e.message(5, false);
  ASSERT_TRUE(readMessage(keyOnly.data(), keyOnly.size(), m, why)) << why;
  EXPECT_TRUE(m.brick.delta.empty());
  EXPECT_LT(keyOnly.size(), bytes.size());
}

TEST(BusFormat, EveryTruncationAndEveryFlippedByteIsRefused) {
  Encoded e;
  const std::vector<uint8_t> bytes = e.message(3);
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_NE(refusal(std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(n))), "") << n;
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_NE(refusal(longer), "");
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<uint8_t> bad = bytes;
    bad[i] ^= 0x10;
    EXPECT_NE(refusal(bad), "") << "byte " << i;
  }
}

TEST(BusFormat, FieldsBehindTheChecksumAreCheckedToo) {
  Encoded e;
  const std::vector<uint8_t> good = e.message(3);
  const size_t brickAt = kHeaderSize + kVolumeSize;
  const auto with = [&](size_t at, const void* value, size_t n) {
    std::vector<uint8_t> m = good;
    std::memcpy(m.data() + at, value, n);
    reseal(m);
    return refusal(m);
  };
  const uint8_t version2 = 2, kindBad = 7, reprBad = 9;
  const uint16_t flagsBad = 2, gridHuge = 60000;
  const uint64_t epoch0 = 0;
  const uint32_t brickOut = 64, version0 = 0, lying = 0xffffffffu;
  const float nan = std::nanf(""), negative = -1.0f, inf = INFINITY;
  EXPECT_NE(with(4, &version2, 1).find("bus format version 2"), std::string::npos);
  EXPECT_NE(with(5, &kindBad, 1).find("kind"), std::string::npos);
  EXPECT_NE(with(6, &flagsBad, 2).find("flags"), std::string::npos);
  EXPECT_NE(with(kHeaderSize, &epoch0, 8).find("epoch"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 17, &reprBad, 1).find("representation"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 20, &gridHuge, 2).find("layout"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 28, &nan, 4).find("bounds"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 40, &inf, 4).find("bounds"), std::string::npos);
  EXPECT_NE(with(brickAt, &brickOut, 4).find("outside"), std::string::npos);
  EXPECT_NE(with(brickAt + 4, &version0, 4).find("version 0"), std::string::npos);
  EXPECT_NE(with(brickAt + 12, &nan, 4).find("change"), std::string::npos);
  EXPECT_NE(with(brickAt + 12, &negative, 4).find("change"), std::string::npos);
  EXPECT_NE(with(brickAt + 16, &lying, 4).find("sections of"), std::string::npos);
  EXPECT_NE(with(brickAt + 20, &lying, 4).find("sections of"), std::string::npos);
  // A section of another brick, or the sections swapped, under a valid checksum.
  const uint32_t otherBrick = 4;
  EXPECT_NE(with(brickAt, &otherBrick, 4).find("the message brick 4"), std::string::npos);
  const std::vector<uint8_t> keyOnly = e.message(3, false);
  Message m;
  std::string why;
  ASSERT_TRUE(readMessage(good.data(), good.size(), m, why));
  Brick swapped = m.brick;
  std::swap(swapped.keyframe, swapped.delta);
  std::vector<uint8_t> bad;
  writeBrickMessage(m.volume, swapped, 0, bad);
  EXPECT_NE(refusal(bad).find("keyframe"), std::string::npos);
  // A volume message with a brick's body is refused by its size.
  std::vector<uint8_t> asVolume = good;
  asVolume[5] = static_cast<uint8_t>(Kind::Volume);
  reseal(asVolume);
  EXPECT_NE(refusal(asVolume).find("volume message has 52"), std::string::npos);
}

}  // namespace
}  // namespace probecast::bus
