// An edge's hub fed by bus messages (no transport): it serves what the producer made, bit for
// bit; versions and epoch are the producer's, so a subscriber resumes on another edge with
// deltas; a new epoch ends streams; redeliveries are ignored and unchecked deltas never served.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/service/bus_format.h"
#include "probecast/service/probe_hub.h"
#include "test_probes.h"

namespace probecast::service {
namespace {

// 16 × 4 × 4 probes 1 m apart in bricks of 4: four bricks.
HubConfig gridConfig() { return hubConfigFor(ProbeGrid{{16, 4, 4}, {{0, 0, 0}, {15, 3, 3}}}, Representation::Zh3); }

// A producer's hub whose bus output is kept as encoded messages.
struct Producer {
  ProbeHub hub{gridConfig()};
  std::vector<std::vector<uint8_t>> messages;
  std::mt19937 rng;
  int frame = 0;
  explicit Producer(unsigned seed = 9) : rng(seed) {
    hub.setBusOutput([this](std::vector<BrickVersionBytes> made) {
      for (size_t i = 0; i < made.size(); ++i) messages.push_back(encode(made[i], i + 1 == made.size()));
    });
  }
  std::vector<uint8_t> encode(const BrickVersionBytes& v, bool last) const {
    std::vector<uint8_t> out;
    bus::writeBrickMessage(hub.volume(), busBrick(v), last ? bus::kEndOfBatch : 0, out);
    return out;
  }
  void publish() { hub.publish(test::movingLightFrame(256, 10 * frame++, 0.01f, rng).data(), nullptr); }
};

ProbeHub::Received feed(ProbeHub& edge, const std::vector<uint8_t>& bytes, std::string* whyOut = nullptr) {
  bus::Message m;
  std::string why;
  EXPECT_TRUE(bus::readMessage(bytes.data(), bytes.size(), m, why)) << why;
  const ProbeHub::Received r = edge.receive(m, true, why);
  if (whyOut) *whyOut = why;
  return r;
}

void feedAll(ProbeHub& edge, const std::vector<std::vector<uint8_t>>& messages, size_t from = 0) {
  for (size_t i = from; i < messages.size(); ++i) feed(edge, messages[i]);
}

// Takes frames until the subscriber holds everything; returns the keyframes among them (and in
// `sections` all sections).
uint32_t drain(ProbeHub& hub, uint64_t id, StreamDecoder& dec, uint32_t* sections = nullptr) {
  uint32_t keyframes = 0;
  while (auto f = hub.nextFrame(id)) {
    EXPECT_EQ(dec.apply(f->payload.data(), f->payload.size()), CodecStatus::Ok);
    keyframes += f->keyframes;
    if (sections) *sections += f->keyframes + f->deltas;
  }
  return keyframes;
}

bool same(const ProbeVolume& a, const float* probes, size_t floats) {
  return a.probes.size() == floats && std::memcmp(a.probes.data(), probes, floats * sizeof(float)) == 0;
}

std::vector<HeldBrick> heldBy(const StreamDecoder& dec) {
  std::vector<HeldBrick> held;
  for (uint32_t b = 0; b < brickCount(dec.layout()); ++b) held.push_back({b, dec.brickVersion(b)});
  return held;
}

TEST(EdgeHub, ServesBitForBitWhatTheProducerMadeWithItsEpoch) {
  Producer p;
  ProbeHub edge(gridConfig(), FromBus{});
  EXPECT_FALSE(edge.ready());
  EXPECT_THROW(edge.publish(test::movingLightFrame(256, 0, 0.0f, p.rng).data(), nullptr), std::logic_error);
  for (int f = 0; f < 5; ++f) p.publish();
  feedAll(edge, p.messages);
  ASSERT_TRUE(edge.ready());
  EXPECT_EQ(edge.epoch(), p.hub.epoch());
  const size_t floats = 256 * kProbeFloats;
  EXPECT_TRUE(same(edge.reconstruction(), p.hub.reconstruction().probes.data(), floats));
  const uint64_t id = edge.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(edge.layout());
  EXPECT_EQ(drain(edge, id, dec), 4u);
  EXPECT_TRUE(same(p.hub.reconstruction(), dec.probes(), floats));
}

// An edge transcodes too: a subscriber asking it for l1 follows the bus versions as they arrive
// and ends holding the edge's l1 stream, which is the producer's volume through l1, bit for bit;
// its epoch is the edge's own, so held l1 versions never pass for the producer's numbers.
TEST(EdgeHub, TranscodesFromTheBusVersionsAsTheyArrive) {
  Producer p;
  ProbeHub edge(gridConfig(), FromBus{});
  p.publish();
  feedAll(edge, p.messages);
  const uint64_t id = edge.addSubscriber(0, 0, {}, nullptr, Representation::L1);
  EXPECT_NE(edge.volumeFor(id).epoch, edge.epoch());
  StreamDecoder dec(edge.volumeFor(id).layout);
  drain(edge, id, dec);
  for (int f = 0; f < 3; ++f) {
    const size_t from = p.messages.size();
    p.publish();
    feedAll(edge, p.messages, from);
    drain(edge, id, dec);
  }
  const size_t floats = 256 * kProbeFloats;
  EXPECT_TRUE(same(edge.reconstruction(Representation::L1), dec.probes(), floats));
  const ProbeVolume through = decodeAs(p.hub.reconstruction(), Representation::L1, false);
  EXPECT_TRUE(same(through, dec.probes(), floats));
}

TEST(EdgeHub, ProbeOffsetsComeOnceInTheVolumeMessageAndTheEdgeWaitsForThem) {
  Producer p;
  const ProbeGrid g = gridOf(p.hub.layout(), p.hub.bounds());
  std::vector<float> offsets(g.count() * 3, 0.0f);
  for (uint32_t i = 0; i < g.count(); ++i) offsets[i * 3 + 1] = 0.01f * static_cast<float>(i % 40);  // cell 1 m
  p.hub.setProbeOffsets(offsets);
  snapProbeOffsets(g, offsets);
  for (int f = 0; f < 2; ++f) p.publish();
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, p.messages);  // brick messages: the offsets' checksum only
  EXPECT_FALSE(edge.ready()) << "an edge must not describe the volume before its offsets arrive";
  std::vector<uint8_t> volume;
  bus::writeVolumeMessage(p.hub.volume(), bus::kEndOfBatch, volume);
  EXPECT_EQ(feed(edge, volume), ProbeHub::Received::Applied);
  ASSERT_TRUE(edge.ready());
  EXPECT_EQ(edge.volume().offsets, p.hub.volume().offsets);
  EXPECT_EQ(edge.reconstruction().offsets, offsets);
  // A volume message of the same epoch with other offsets is refused and changes nothing.
  bus::Volume other = p.hub.volume();
  other.offsets[7] = static_cast<int8_t>(other.offsets[7] + 1);
  bus::writeVolumeMessage(other, 0, volume);
  std::string why;
  EXPECT_EQ(feed(edge, volume, &why), ProbeHub::Received::Refused);
  EXPECT_NE(why.find("another volume"), std::string::npos) << why;
  EXPECT_EQ(edge.reconstruction().offsets, offsets);
}

// The scene: brick messages name its hash and carry the state of their frame; the manifest comes
// in the volume message, and the edge describes nothing before it has it. Subscribers' frames
// carry the newest state, as the producer's do.
TEST(EdgeHub, TheSceneAndItsStateComeThroughTheBus) {
  Producer p;
  SceneStamp stamp;
  stamp.hash.fill(0x42);
  stamp.manifest = R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})";
  p.hub.setScene(stamp);
  bus::SceneState st;
  st.rate = 0.25;
  st.clockUs = 1764950000000000ull;
  st.lights.resize(1);
  for (int f = 0; f < 3; ++f) {
    st.time = 0.5 * f;
    st.lights[0].position[0] = static_cast<float>(f);
    p.hub.setSceneState(st);
    p.publish();
  }
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, p.messages);
  EXPECT_FALSE(edge.ready()) << "an edge must not describe the volume before the scene's manifest arrives";
  std::vector<uint8_t> volume;
  bus::writeVolumeMessage(p.hub.volume(), bus::kEndOfBatch, volume);
  EXPECT_EQ(feed(edge, volume), ProbeHub::Received::Applied);
  ASSERT_TRUE(edge.ready());
  EXPECT_EQ(edge.volume().sceneHash, stamp.hash);
  EXPECT_EQ(edge.volume().sceneManifest, stamp.manifest);
  EXPECT_EQ(edge.sceneState(), st);  // the newest frame's, whatever order its bricks came in
  const uint64_t id = edge.addSubscriber(0, 0, {}, [] {});
  const auto frame = edge.nextFrame(id);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->state, st);
  EXPECT_EQ(edge.reconstruction().scene.time, 1.0);
  // Another scene in the same epoch is refused; a new scene is a new epoch.
  bus::Volume other = p.hub.volume();
  other.sceneHash[0] ^= 1;
  bus::writeVolumeMessage(other, 0, volume);
  std::string why;
  EXPECT_EQ(feed(edge, volume, &why), ProbeHub::Received::Refused);
  EXPECT_NE(why.find("another volume"), std::string::npos) << why;
  const uint64_t epoch = p.hub.epoch();
  stamp.hash.fill(0x43);
  p.hub.setScene(stamp);
  EXPECT_NE(p.hub.epoch(), epoch);
}

// Every bus message states the area light rule: an edge describes its volume with the producer's,
// a message of the same epoch with another rule is refused, and a new rule is a new epoch.
TEST(EdgeHub, TheAreaLightRuleComesWithEveryMessageAndAChangeIsANewEpoch) {
  Producer p;
  const AreaLightRule rule{kAreaLightRuleVersion, 0.2f};
  p.hub.setAreaLightRule(rule);
  for (int f = 0; f < 2; ++f) p.publish();
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, p.messages);
  ASSERT_TRUE(edge.ready());
  EXPECT_EQ(edge.volume().areaLights, rule);
  EXPECT_EQ(edge.reconstruction().areaLights, rule);
  bus::Volume other = p.hub.volume();
  other.areaLights.minPowerFraction = 0.3f;
  std::vector<uint8_t> volume;
  bus::writeVolumeMessage(other, 0, volume);
  std::string why;
  EXPECT_EQ(feed(edge, volume, &why), ProbeHub::Received::Refused);
  EXPECT_NE(why.find("another volume"), std::string::npos) << why;
  EXPECT_EQ(edge.volume().areaLights, rule);
  const uint64_t epoch = p.hub.epoch();
  p.hub.setAreaLightRule({});  // off after publishing: what subscribers were told no longer holds
  EXPECT_NE(p.hub.epoch(), epoch);
  p.publish();
  EXPECT_EQ(feed(edge, p.messages.back()), ProbeHub::Received::NewEpoch);
  EXPECT_FALSE(edge.volume().areaLights.on());
}

TEST(EdgeHub, ASubscriberMovingToAnotherEdgeResumesWithDeltas) {
  Producer p;
  ProbeHub a(gridConfig(), FromBus{}), b(gridConfig(), FromBus{});
  for (int f = 0; f < 3; ++f) p.publish();
  feedAll(a, p.messages);
  feedAll(b, p.messages);
  const uint64_t onA = a.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(a.layout());
  drain(a, onA, dec);
  a.removeSubscriber(onA);  // edge a goes away
  const size_t seen = p.messages.size();
  p.publish();  // one version on
  feedAll(b, p.messages, seen);
  const uint64_t onB = b.addSubscriber(0, a.epoch(), heldBy(dec), nullptr);
  const auto frame = b.nextFrame(onB);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->keyframes, 0u);
  EXPECT_EQ(frame->deltas, 4u);
  ASSERT_EQ(dec.apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
  EXPECT_TRUE(same(p.hub.reconstruction(), dec.probes(), 256 * kProbeFloats));
}

TEST(EdgeHub, LateEdgeFromTheNewestMessagesServesKeyframesThenDeltas) {
  Producer p;
  for (int f = 0; f < 4; ++f) p.publish();
  // What a store keeping one message per brick holds: the newest of each.
  std::vector<std::vector<uint8_t>> newest(4);
  for (const auto& m : p.messages) {
    bus::Message parsed;
    std::string why;
    ASSERT_TRUE(bus::readMessage(m.data(), m.size(), parsed, why));
    newest[parsed.brick.brick] = m;
  }
  ProbeHub late(gridConfig(), FromBus{});
  feedAll(late, newest);
  EXPECT_TRUE(same(late.reconstruction(), p.hub.reconstruction().probes.data(), 256 * kProbeFloats));
  // Its deltas could not be checked (the versions before never arrived): a holder one version
  // behind gets keyframes now, and deltas again from the next version on.
  const size_t seen = p.messages.size();
  p.publish();
  feedAll(late, p.messages, seen);
  const uint64_t id = late.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(late.layout());
  EXPECT_EQ(drain(late, id, dec), 4u);
  const size_t seen2 = p.messages.size();
  p.publish();
  feedAll(late, p.messages, seen2);
  EXPECT_EQ(drain(late, id, dec), 0u);
  EXPECT_TRUE(same(p.hub.reconstruction(), dec.probes(), 256 * kProbeFloats));
}

TEST(EdgeHub, ANewEpochEndsEveryStreamAndVoidsWhatWasHeld) {
  Producer first;
  first.publish();
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, first.messages);
  int woken = 0;
  const uint64_t id = edge.addSubscriber(0, 0, {}, [&] { ++woken; });
  StreamDecoder dec(edge.layout());
  drain(edge, id, dec);
  EXPECT_FALSE(edge.streamEnded(id));
  Producer restarted;  // another hub: another epoch
  restarted.publish();
  ASSERT_NE(restarted.hub.epoch(), first.hub.epoch());
  EXPECT_EQ(feed(edge, restarted.messages[0]), ProbeHub::Received::NewEpoch);
  EXPECT_TRUE(edge.streamEnded(id));
  EXPECT_GE(woken, 1);
  EXPECT_FALSE(edge.nextFrame(id).has_value());
  feedAll(edge, restarted.messages, 1);
  EXPECT_EQ(edge.epoch(), restarted.hub.epoch());
  const uint64_t again = edge.addSubscriber(0, first.hub.epoch(), heldBy(dec), nullptr);
  StreamDecoder fresh(edge.layout());
  uint32_t sections = 0;
  drain(edge, again, fresh, &sections);
  EXPECT_EQ(sections, 4u);  // the old epoch's versions count for nothing: every brick is sent
  EXPECT_TRUE(same(restarted.hub.reconstruction(), fresh.probes(), 256 * kProbeFloats));
}

TEST(EdgeHub, RedeliveriesAreStaleAndADeltaThatMissesItsKeyframeIsNeverServed) {
  Producer p, other(11);
  p.publish();
  other.publish();
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, p.messages);
  EXPECT_EQ(feed(edge, p.messages[0]), ProbeHub::Received::Stale);
  const uint64_t id = edge.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(edge.layout());
  drain(edge, id, dec);
  // Version 2 of brick 0 with p's keyframe but the delta of other lighting: a valid section
  // that does not reach the keyframe's probes.
  const size_t seen = p.messages.size();
  p.publish();
  other.publish();
  bus::Message good, foreign;
  std::string why;
  ASSERT_TRUE(bus::readMessage(p.messages[seen].data(), p.messages[seen].size(), good, why));
  for (size_t i = 1; i < other.messages.size(); ++i) {
    ASSERT_TRUE(bus::readMessage(other.messages[i].data(), other.messages[i].size(), foreign, why));
    if (foreign.brick.brick == good.brick.brick && foreign.brick.version == good.brick.version) break;
  }
  ASSERT_EQ(foreign.brick.brick, good.brick.brick);
  bus::Brick mixed = good.brick;
  mixed.delta = foreign.brick.delta;
  std::vector<uint8_t> bytes;
  bus::writeBrickMessage(good.volume, mixed, bus::kEndOfBatch, bytes);
  EXPECT_EQ(feed(edge, bytes, &why), ProbeHub::Received::Applied);
  EXPECT_NE(why.find("delta dropped"), std::string::npos) << why;
  const auto frame = edge.nextFrame(id);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->deltas, 0u);
  EXPECT_EQ(frame->keyframes, 1u);
  ASSERT_EQ(dec.apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
  EXPECT_TRUE(same(edge.reconstruction(), dec.probes(), 256 * kProbeFloats));
}

TEST(EdgeHub, AKeyframeThatDoesNotDecodeIsRefusedAndNothingChanges) {
  Producer p;
  p.publish();
  ProbeHub edge(gridConfig(), FromBus{});
  feedAll(edge, p.messages);
  const ProbeVolume before = edge.reconstruction();
  const size_t seen = p.messages.size();
  p.publish();
  bus::Message m;
  std::string why;
  ASSERT_TRUE(bus::readMessage(p.messages[seen].data(), p.messages[seen].size(), m, why));
  // A keyframe section whose header and CRC are valid but whose payload is of another size.
  SectionBytes at;
  ASSERT_TRUE(locateSection(m.brick.keyframe.data(), m.brick.keyframe.size(), &at));
  const std::vector<uint8_t> shorter(m.brick.keyframe.begin() + at.dataAt, m.brick.keyframe.end() - 1);
  // Stored raw (the zstd bit cleared), so the container checks out and only decoding can tell.
  const uint8_t rawKind = static_cast<uint8_t>(m.brick.keyframe[at.kindAt] & ~0x04);
  const std::vector<uint8_t> key = sealSection(m.brick.brick, m.brick.version, rawKind, shorter);
  bus::Brick bad = m.brick;
  bad.keyframe = key;
  bad.delta = {};
  std::vector<uint8_t> bytes;
  bus::writeBrickMessage(m.volume, bad, bus::kEndOfBatch, bytes);
  bus::Message parsed;
  ASSERT_TRUE(bus::readMessage(bytes.data(), bytes.size(), parsed, why)) << why;
  EXPECT_EQ(edge.receive(parsed, true, why), ProbeHub::Received::Refused);
  EXPECT_NE(why.find("keyframe does not decode"), std::string::npos) << why;
  EXPECT_EQ(edge.reconstruction().probes, before.probes);
}

TEST(EdgeHub, ASubscriberAheadOfALaggingEdgeIsSentNothingOlderThanItHolds) {
  Producer p;
  ProbeHub ahead(gridConfig(), FromBus{}), lagging(gridConfig(), FromBus{});
  p.publish();
  const size_t first = p.messages.size();
  p.publish();
  feedAll(ahead, p.messages);
  feedAll(lagging, std::vector<std::vector<uint8_t>>(p.messages.begin(), p.messages.begin() + first));
  const uint64_t onAhead = ahead.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(ahead.layout());
  drain(ahead, onAhead, dec);  // holds version 2 of every brick; the lagging edge has version 1
  const uint64_t moved = lagging.addSubscriber(0, ahead.epoch(), heldBy(dec), nullptr);
  EXPECT_FALSE(lagging.nextFrame(moved).has_value());  // an older keyframe would be refused by its decoder
  feedAll(lagging, p.messages, first);  // the lagging edge catches up to what it holds: still nothing to send
  EXPECT_FALSE(lagging.nextFrame(moved).has_value());
  const size_t seen = p.messages.size();
  p.publish();
  feedAll(lagging, p.messages, seen);
  const auto frame = lagging.nextFrame(moved);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->deltas, 4u);
  EXPECT_EQ(dec.apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
  EXPECT_TRUE(same(p.hub.reconstruction(), dec.probes(), 256 * kProbeFloats));
}

}  // namespace
}  // namespace probecast::service
