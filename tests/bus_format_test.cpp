// The probe bus format: golden bytes, round trips, and refusal of every malformed message with a
// reason (truncations, corruptions, lying sizes, sections that are not what the message says).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
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
  v.areaLights = {kAreaLightRuleVersion, 0.25f};
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
  // Written out by hand from the format in bus_format.h (bus format 4, codec format 4); the
  // CRC-32C is of bytes 0-11 and 16-117, computed independently.
  const uint8_t golden[] = {
      0x50, 0x43, 0x42, 0x4d, 0x04, 0x01, 0x01, 0x00, 0x66, 0x00, 0x00, 0x00, 0x4d, 0x3a, 0xfa, 0x93,  // header
      0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11,  // epoch, time
      0x04, 0x03, 0x04, 0x00, 0x10, 0x00, 0x04, 0x00, 0x10, 0x00, 0x00, 0x00,                          // layout, no offsets
      0x00, 0x00, 0x00, 0xc0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xc0,                          // min
      0x00, 0x00, 0xc0, 0x3f, 0x00, 0x00, 0xc0, 0x3f, 0x00, 0x00, 0xb0, 0x40,                          // max
      0x00, 0x00, 0x00, 0x00,                                                                          // offsets CRC
      0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3e,                                                  // area light rule
      0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0x0b, 0x0c, 0x0d, 0x0e, 0x0f,  // scene hash
      0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x1b, 0x1c, 0x1d, 0x1e, 0x1f,
      0x02, 0x00, 0x00, 0x00, 0x7b, 0x7d};                                                             // manifest "{}"
  Volume named = sampleVolume();
  for (uint8_t i = 0; i < 32; ++i) named.sceneHash[i] = i;
  named.sceneManifest = "{}";
  std::vector<uint8_t> out;
  writeVolumeMessage(named, kEndOfBatch, out);
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
  EXPECT_EQ(m.volume.areaLights, (AreaLightRule{kAreaLightRuleVersion, 0.25f}));
  EXPECT_EQ(m.volume.sceneHash, named.sceneHash);
  EXPECT_EQ(m.volume.sceneManifest, "{}");
  // A version 3 message (no scene) is refused by its version, not misread.
  std::vector<uint8_t> v3(std::begin(golden), std::end(golden));
  v3[4] = 3;
  reseal(v3);
  EXPECT_NE(refusal(v3).find("bus format version 3, this build reads 4"), std::string::npos) << refusal(v3);
  // A hash without a manifest (and a manifest without a hash) under a valid checksum.
  std::vector<uint8_t> noManifest;
  Volume hashOnly = named;
  hashOnly.sceneManifest.clear();
  writeVolumeMessage(hashOnly, 0, noManifest);
  EXPECT_NE(refusal(noManifest).find("scene hash without a manifest"), std::string::npos) << refusal(noManifest);
  // The same message from a build that wrote codec format 3 (no Rice-coded deltas; bare sections
  // carry no version of their own) is refused, saying so, not misread.
  std::vector<uint8_t> older(std::begin(golden), std::end(golden));
  older[32] = 3;
  reseal(older);
  EXPECT_NE(refusal(older).find("codec format version 3"), std::string::npos) << refusal(older);
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
  const uint8_t version1 = 1, version2 = 2, kindBad = 7, reprBad = 9;
  const uint16_t flagsBad = 2, gridHuge = 60000;
  const uint64_t epoch0 = 0;
  const uint32_t brickOut = 64, version0 = 0, lying = 0xffffffffu;
  const float nan = std::nanf(""), negative = -1.0f, inf = INFINITY;
  EXPECT_NE(with(4, &version1, 1).find("bus format version 1"), std::string::npos);  // before the offsets
  EXPECT_NE(with(4, &version2, 1).find("bus format version 2"), std::string::npos);  // before the rule
  const uint32_t ruleUnknown = 2;
  const float share = 1.5f;
  EXPECT_NE(with(kHeaderSize + 56, &ruleUnknown, 4).find("rule version 2 is unknown"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 60, &share, 4).find("power share"), std::string::npos);
  EXPECT_NE(with(kHeaderSize + 60, &nan, 4).find("power share"), std::string::npos);
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
  EXPECT_NE(refusal(asVolume).find("manifest"), std::string::npos) << refusal(asVolume);
}

SceneState sampleState() {
  SceneState st;
  st.time = 12.375;
  st.rate = 0.05;
  st.clockUs = 1764950000123456ull;
  LightState point;
  point.position[1] = 1.9f;
  point.color[0] = 0.5f;
  point.intensity = 20.0f;
  LightState spot;
  spot.type = 1;
  spot.direction[0] = 0.6f;
  spot.direction[1] = -0.8f;
  spot.innerCone = 0.2f;
  spot.outerCone = 0.5f;
  spot.range = 10.0f;
  st.lights = {point, spot};
  return st;
}

TEST(BusFormat, BrickMessagesCarryTheSceneStateOfTheirFrame) {
  Encoded e;
  Message m;
  std::string why;
  std::vector<uint8_t> bytes = e.message(6);
  ASSERT_TRUE(readMessage(bytes.data(), bytes.size(), m, why)) << why;
  EXPECT_EQ(m.brick.state, SceneState{});  // a frame of no known state: time 0, still, no lights
  Brick b = m.brick;
  b.state = sampleState();
  std::vector<uint8_t> withState;
  writeBrickMessage(m.volume, b, 0, withState);
  EXPECT_EQ(withState.size(), bytes.size() + 2 * kLightStateSize);
  ASSERT_TRUE(readMessage(withState.data(), withState.size(), m, why)) << why;
  EXPECT_EQ(m.brick.state, sampleState());
  // The state's fields as the format places them: time right after the brick's fixed part.
  const size_t at = kHeaderSize + kVolumeSize + kBrickFixedSize;
  double time = 0.0;
  uint32_t lights = 0;
  std::memcpy(&time, withState.data() + at, 8);
  std::memcpy(&lights, withState.data() + at + 24, 4);
  EXPECT_EQ(time, 12.375);
  EXPECT_EQ(lights, 2u);
  // Nonsense states under a valid checksum, each refused with its reason.
  const auto refusedWith = [&](const std::function<void(SceneState&)>& breakIt, const std::string& reason) {
    Brick bad = b;
    breakIt(bad.state);
    std::vector<uint8_t> out;
    writeBrickMessage(m.volume, bad, 0, out);
    EXPECT_NE(refusal(out).find(reason), std::string::npos) << refusal(out);
  };
  refusedWith([](SceneState& s) { s.time = std::nan(""); }, "scene time is not finite");
  refusedWith([](SceneState& s) { s.rate = 1e9; }, "playback rate");
  refusedWith([](SceneState& s) { s.lights[1].type = 7; }, "unknown type 7");
  refusedWith([](SceneState& s) { s.lights[0].direction[1] = 0.0f; }, "not unit length");
  refusedWith([](SceneState& s) { s.lights[0].intensity = -1.0f; }, "negative intensity");
  refusedWith([](SceneState& s) { s.lights[1].innerCone = 0.9f; }, "cone angles");
  refusedWith([](SceneState& s) { s.lights[0].color[2] = std::numeric_limits<float>::infinity(); }, "NaN or Inf");
  refusedWith([](SceneState& s) { s.lights.resize(65); }, "65 lights");
  // A light count that runs past the message.
  std::vector<uint8_t> lying = withState;
  const uint32_t many = 60;
  std::memcpy(lying.data() + at + 24, &many, 4);
  reseal(lying);
  EXPECT_NE(refusal(lying).find("truncated in its scene state"), std::string::npos) << refusal(lying);
}

// Sample offsets for the sample volume: probe p moves (p % 7 - 3) × 20 steps along x and 5 along z.
std::vector<int8_t> sampleOffsets() {
  std::vector<int8_t> q(16 * 4 * 16 * 3, 0);
  for (size_t p = 0; p < q.size() / 3; ++p) {
    q[p * 3] = static_cast<int8_t>((static_cast<int>(p % 7) - 3) * 20);
    q[p * 3 + 2] = 5;
  }
  return q;
}

TEST(BusFormat, OffsetsTravelOnceInTheVolumeMessageAndBrickMessagesCarryTheirChecksum) {
  Volume v = sampleVolume();
  v.offsets = sampleOffsets();
  std::vector<uint8_t> volumeBytes, plainBytes;
  writeVolumeMessage(v, 0, volumeBytes);
  writeVolumeMessage(sampleVolume(), 0, plainBytes);
  EXPECT_EQ(volumeBytes.size(), plainBytes.size() + 16 * 4 * 16 * 3);  // 3 bytes per probe, once
  Message m;
  std::string why;
  ASSERT_TRUE(readMessage(volumeBytes.data(), volumeBytes.size(), m, why)) << why;
  EXPECT_EQ(m.volume.offsets, v.offsets);
  EXPECT_TRUE(m.volume.hasOffsets);
  EXPECT_EQ(m.volume.offsetsCrc, offsetsChecksum(v.offsets));
  std::vector<uint8_t> again;
  writeVolumeMessage(m.volume, m.flags, again);
  EXPECT_EQ(again, volumeBytes);

  // A brick message of that volume: the same size as without offsets, announcing their checksum.
  Encoded e;
  Brick b;
  b.brick = 2;
  b.version = e.encoder.brickVersion(2);
  b.keyframe = e.keyframes[2];
  std::vector<uint8_t> brickBytes, plainBrick;
  writeBrickMessage(v, b, 0, brickBytes);
  writeBrickMessage(sampleVolume(), b, 0, plainBrick);
  EXPECT_EQ(brickBytes.size(), plainBrick.size());
  ASSERT_TRUE(readMessage(brickBytes.data(), brickBytes.size(), m, why)) << why;
  EXPECT_TRUE(m.volume.hasOffsets);
  EXPECT_TRUE(m.volume.offsets.empty());
  EXPECT_EQ(m.volume.offsetsCrc, offsetsChecksum(v.offsets));
  writeBrickMessage(m.volume, m.brick, m.flags, again);
  EXPECT_EQ(again, brickBytes);
}

TEST(BusFormat, MalformedOffsetsAreRefused) {
  Volume v = sampleVolume();
  v.offsets = sampleOffsets();
  std::vector<uint8_t> good;
  writeVolumeMessage(v, 0, good);
  const size_t at = kHeaderSize + kVolumeSize + 4;  // the first offset byte (after an empty manifest)
  // One offset byte short (sizes and checksums made consistent): the count is wrong.
  std::vector<uint8_t> shorter(good.begin(), good.end() - 1);
  const uint32_t body = static_cast<uint32_t>(shorter.size() - kHeaderSize);
  std::memcpy(shorter.data() + 8, &body, 4);
  reseal(shorter);
  EXPECT_NE(refusal(shorter).find("3071 offset bytes, its volume 3072"), std::string::npos) << refusal(shorter);
  // -128 steps (outside the symmetric range), with the offsets checksum made to match.
  std::vector<uint8_t> beyond = good;
  beyond[at + 3 * 9 + 2] = 0x80;
  const uint32_t crc = crc32c(beyond.data() + at, 16 * 4 * 16 * 3);
  std::memcpy(beyond.data() + kHeaderSize + 52, &crc, 4);
  reseal(beyond);
  EXPECT_NE(refusal(beyond).find("probe 9 z offset of -128 steps"), std::string::npos) << refusal(beyond);
  // Offsets that are not the ones announced.
  std::vector<uint8_t> changed = good;
  changed[at + 4] ^= 1;
  reseal(changed);
  EXPECT_NE(refusal(changed).find("checksum"), std::string::npos);
  // A flag that is neither 0 nor 1, and a checksum without offsets.
  std::vector<uint8_t> flag = good;
  flag[kHeaderSize + 19] = 2;
  reseal(flag);
  EXPECT_NE(refusal(flag).find("offsets flag 2"), std::string::npos);
  std::vector<uint8_t> plain;
  writeVolumeMessage(sampleVolume(), 0, plain);
  const uint32_t someCrc = 7;
  std::memcpy(plain.data() + kHeaderSize + 52, &someCrc, 4);
  reseal(plain);
  EXPECT_NE(refusal(plain).find("announces an offsets checksum"), std::string::npos);
  // Movement along an axis of one probe.
  Volume flat = sampleVolume();
  flat.layout.grid[1] = 1;
  flat.offsets.assign(16 * 1 * 16 * 3, 0);
  flat.offsets[3 * 4 + 1] = 1;
  std::vector<uint8_t> flatBytes;
  writeVolumeMessage(flat, 0, flatBytes);
  EXPECT_NE(refusal(flatBytes).find("an axis of one probe"), std::string::npos) << refusal(flatBytes);
}

}  // namespace
}  // namespace probecast::bus
