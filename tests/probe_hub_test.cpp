// The transport-free hub: encode once, priority under budgets, stale versions skipped, resume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <random>
#include <thread>

#include "probecast/service/probe_hub.h"
#include "test_probes.h"

namespace probecast::service {
namespace {

HubConfig rowConfig() {
  // 16 × 4 × 4 probes, bricks of 4: four bricks along x, probes 1 m apart.
  HubConfig c;
  c.layout.grid[0] = 16;
  c.layout.grid[1] = 4;
  c.layout.grid[2] = 4;
  c.layout.brickDim = 4;
  c.layout.repr = Representation::L2;
  c.bounds.max[0] = 15;
  c.bounds.max[1] = 3;
  c.bounds.max[2] = 3;
  return c;
}

// Orthographic view down −z over x in [cx − h, cx + h].
View viewOver(float cx, float h) {
  View v{};
  v.viewProj[0] = 1.0f / h;
  v.viewProj[5] = 1.0f / h;
  v.viewProj[10] = -1.0f / 40.0f;
  v.viewProj[12] = -cx / h;
  v.viewProj[13] = -1.5f / h;
  v.viewProj[14] = 20.0f / 40.0f;
  v.viewProj[15] = 1.0f;
  v.eye[0] = cx;
  v.eye[1] = 1.5f;
  v.eye[2] = 20.0f;
  return v;
}

std::vector<uint32_t> bricksIn(const OutgoingFrame& f, StreamDecoder& dec) {
  std::vector<uint32_t> before(brickCount(dec.layout()));
  for (uint32_t b = 0; b < before.size(); ++b) before[b] = dec.brickVersion(b);
  EXPECT_EQ(dec.apply(f.payload.data(), f.payload.size()), CodecStatus::Ok);
  std::vector<uint32_t> got;
  for (uint32_t b = 0; b < before.size(); ++b)
    if (dec.brickVersion(b) != before[b]) got.push_back(b);
  return got;
}

TEST(ProbeHub, InViewBricksComeFirstUnderABudget) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(1);
  const auto probes = test::movingLightFrame(256, 0, 0.01f, rng);
  hub.publish(probes.data(), nullptr);
  // Budget for about one keyframe brick per frame (a 4³ L2 brick is ~1.9 kB raw).
  const uint64_t id = hub.addSubscriber(2000, 0, {}, nullptr);
  hub.setViews(id, {viewOver(13.5f, 1.0f)});  // sees brick 3 only
  StreamDecoder dec(hub.layout());
  const auto first = hub.nextFrame(id);
  ASSERT_TRUE(first.has_value());
  const auto got = bricksIn(*first, dec);
  ASSERT_FALSE(got.empty());
  EXPECT_NE(std::find(got.begin(), got.end(), 3u), got.end());  // the brick in view
  EXPECT_EQ(std::find(got.begin(), got.end(), 0u), got.end());  // not the farthest one out of view
  EXPECT_LT(got.size(), 4u);                                     // the budget held the rest back
}

TEST(ProbeHub, AnUnlimitedBudgetTakesEveryStaleBrickInOneFrameWhateverItsView) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(4);
  hub.publish(test::movingLightFrame(256, 0, 0.01f, rng).data(), nullptr);
  const uint64_t id = hub.addSubscriber(0, 0, {}, nullptr);
  hub.setViews(id, {viewOver(13.5f, 1.0f)});  // sees brick 3 only
  StreamDecoder dec(hub.layout());
  auto first = hub.nextFrame(id);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(bricksIn(*first, dec), (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(first->keyframes + first->deltas, 4u);
  EXPECT_FALSE(hub.nextFrame(id).has_value());  // holds everything
  hub.publish(test::movingLightFrame(256, 6, 0.01f, rng).data(), nullptr);
  auto second = hub.nextFrame(id);
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(bricksIn(*second, dec), (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(second->deltas, 4u);
  EXPECT_EQ(hub.stats(id).bricksBehind, 0u);
}

TEST(ProbeHub, WhereBricksOutOfViewWeighNothingAnUnlimitedBudgetStillLeavesThemOut) {
  HubConfig c = rowConfig();
  c.priority.outOfViewWeight = 0.0f;
  ProbeHub hub(c);
  std::mt19937 rng(5);
  hub.publish(test::movingLightFrame(256, 0, 0.01f, rng).data(), nullptr);
  const uint64_t id = hub.addSubscriber(0, 0, {}, nullptr);
  hub.setViews(id, {viewOver(13.5f, 1.0f)});
  StreamDecoder dec(hub.layout());
  auto first = hub.nextFrame(id);
  ASSERT_TRUE(first.has_value());
  const auto got = bricksIn(*first, dec);
  EXPECT_NE(std::find(got.begin(), got.end(), 3u), got.end());
  EXPECT_EQ(std::find(got.begin(), got.end(), 0u), got.end());
}

TEST(ProbeHub, EncodedOnceSameBytesForEverySubscriber) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(2);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  const uint64_t a = hub.addSubscriber(0, 0, {}, nullptr), b = hub.addSubscriber(0, 0, {}, nullptr);
  auto fa = hub.nextFrame(a), fb = hub.nextFrame(b);
  ASSERT_TRUE(fa && fb);
  // Same sections; only the header's sequence and CRC could differ, and both are frame 1.
  EXPECT_EQ(fa->payload, fb->payload);
  EXPECT_FALSE(hub.nextFrame(a).has_value());  // holds everything now
}

// With the noise rule (c = 2, σ = 0.01: c·σ = 0.02), view weights hold what nobody sees longer: a
// DC change of 0.1 (0.061 in the rule's irradiance-weighted RMS, within 4c·σ = 0.08) reaches the
// probes of weight 1 (x < 8) and not those of weight 0; once the weights are cleared it reaches
// every probe. Weights that nobody sees anything by (all 0) count as none.
TEST(ProbeHub, ViewWeightsHoldTheProbesNobodySeesWithinFourCSigma) {
  HubConfig config = rowConfig();
  config.encoder.noiseScale = 2.0f;
  ProbeHub hub(config);
  const uint32_t count = 256;
  const auto grey = [&](float dc) {
    std::vector<float> p(static_cast<size_t>(count) * kProbeFloats, 0.0f);
    for (uint32_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) p[static_cast<size_t>(i) * kProbeFloats + c] = dc;
    return p;
  };
  const std::vector<float> noise(count, 0.01f);
  std::vector<float> weights(count, 0.0f);
  for (uint32_t i = 0; i < count; ++i) weights[i] = i % 16 < 8 ? 1.0f : 0.0f;
  const auto heldDc = [&](uint32_t probe) { return hub.reconstruction().probes[static_cast<size_t>(probe) * kProbeFloats]; };
  hub.publish(grey(1.0f).data(), nullptr, noise.data());
  hub.setViewWeights(std::vector<float>(count, 0.0f));  // nobody sees anything: every probe alike
  hub.publish(grey(1.1f).data(), nullptr, noise.data());
  EXPECT_NEAR(heldDc(3), 1.1f, 0.005f);
  EXPECT_NEAR(heldDc(12), 1.1f, 0.005f);
  hub.setViewWeights(weights);
  hub.publish(grey(1.2f).data(), nullptr, noise.data());
  EXPECT_NEAR(heldDc(3), 1.2f, 0.005f);    // x = 3: seen
  EXPECT_NEAR(heldDc(12), 1.1f, 0.005f);   // x = 12: nobody sees it
  EXPECT_NEAR(heldDc(16 * 3 + 12), 1.1f, 0.005f);
  hub.setViewWeights({});
  hub.publish(grey(1.2f).data(), nullptr, noise.data());
  EXPECT_NEAR(heldDc(12), 1.2f, 0.005f);
}

// A published volume's stillUpdates reach the encoder's refinement interval (4 here, c = 2, σ =
// 0.01): a DC step of 0.05 (0.031 in the rule's RMS, between c·σ and 2c·σ) is a refinement and waits
// for update 4 in probes still for 100 updates, but goes at once in those whose light changed 1
// update ago (x < 8), and without stillUpdates every probe counts as still.
TEST(ProbeHub, APublishedVolumesStillUpdatesReachTheRefinementInterval) {
  for (bool given : {true, false}) {
    HubConfig config = rowConfig();
    config.encoder.noiseScale = 2.0f;
    config.encoder.refinementInterval = 4;
    ProbeHub hub(config);
    ProbeVolume v = makeProbeVolume(gridOf(config.layout, config.bounds));
    const uint32_t count = v.count();
    const auto setDc = [&](float dc) {
      for (uint32_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c) v.probes[static_cast<size_t>(i) * kProbeFloats + c] = dc;
    };
    v.noise.assign(count, 0.01f);
    if (given) {
      v.stillUpdates.assign(count, 100);
      for (uint32_t i = 0; i < count; ++i)
        if (i % 16 < 8) v.stillUpdates[i] = 1;
    }
    const auto heldDc = [&](uint32_t probe) {
      return hub.reconstruction().probes[static_cast<size_t>(probe) * kProbeFloats];
    };
    setDc(1.0f);
    hub.publish(v);  // update 1
    setDc(1.05f);
    hub.publish(v);  // update 2
    EXPECT_NEAR(heldDc(3), given ? 1.05f : 1.0f, 0.005f) << "x = 3, stillUpdates given: " << given;
    EXPECT_NEAR(heldDc(12), 1.0f, 0.005f) << "x = 12, stillUpdates given: " << given;
    hub.publish(v);  // update 3
    hub.publish(v);  // update 4: the interval
    EXPECT_NEAR(heldDc(12), 1.05f, 0.005f) << "x = 12, stillUpdates given: " << given;
  }
}

TEST(ProbeHub, AcksCountAppliedFramesAndRefuseFramesNeverSent) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(3);
  const uint64_t id = hub.addSubscriber(0, 0, {}, nullptr);
  std::string why;
  EXPECT_FALSE(hub.acknowledge(id, 1, why));  // nothing sent yet
  EXPECT_NE(why.find("only 0"), std::string::npos);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  ASSERT_TRUE(hub.nextFrame(id));
  hub.publish(test::movingLightFrame(256, 1, 0.1f, rng).data(), nullptr);
  ASSERT_TRUE(hub.nextFrame(id));
  EXPECT_TRUE(hub.acknowledge(id, 1, why));
  EXPECT_EQ(hub.stats(id).framesAcked, 1u);
  EXPECT_TRUE(hub.acknowledge(id, 2, why));
  EXPECT_EQ(hub.stats(id).framesAcked, 2u);
  EXPECT_FALSE(hub.acknowledge(id, 1, why));  // backwards
  EXPECT_FALSE(hub.acknowledge(id, 3, why));  // never sent
  EXPECT_EQ(hub.stats(id).framesAcked, 2u);
}

HubConfig largeConfig() {
  // 64 × 16 × 16 probes of L2 in bricks of 4: 256 bricks, noisy ones of about 0.5 kB each.
  HubConfig c = rowConfig();
  c.layout.grid[0] = 64;
  c.layout.grid[1] = 16;
  c.layout.grid[2] = 16;
  c.bounds.max[0] = 63;
  c.bounds.max[1] = 15;
  c.bounds.max[2] = 15;
  return c;
}

TEST(ProbeHub, APacedSubscriberWaitsForItsWindowAndAnAckWakesIt) {
  ProbeHub hub(largeConfig());
  std::mt19937 rng(5);
  const int probes = 64 * 16 * 16;
  hub.publish(test::movingLightFrame(probes, 0, 0.3f, rng).data(), nullptr);  // noisy: bricks of ~1.5 kB
  int wakes = 0;
  const uint64_t id = hub.addSubscriber(0, 0, {}, [&] { ++wakes; }, std::nullopt, /*paced=*/true);
  const uint64_t unpaced = hub.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(hub.layout());
  // Before anything is measured, the initial window, in frames of at most a quarter of it (the
  // first one fits a fresh connection's first flight): part of the volume, best bricks first.
  std::vector<OutgoingFrame> sent;
  uint64_t bytes = 0;
  while (auto f = hub.nextFrame(id)) {
    EXPECT_LE(f->payloadBytes, (sent.empty() ? LinkEstimator::kFirstFrame : LinkEstimator::kInitialWindow / 4) + 2048);
    bytes += f->payloadBytes;
    bricksIn(*f, dec);
    sent.push_back(*f);
    ASSERT_LE(sent.size(), 8u);
  }
  EXPECT_GE(sent.size(), 3u);
  EXPECT_LE(bytes, LinkEstimator::kInitialWindow + 2048);
  EXPECT_GT(bytes, LinkEstimator::kInitialWindow / 2);
  EXPECT_TRUE(hub.stats(id).paced);
  EXPECT_EQ(hub.stats(id).link.windowWaits, 1u);  // the window is full
  EXPECT_GT(hub.stats(id).bricksBehind, 0u);
  const OutgoingFrame* first = &sent.back();
  // An unpaced subscriber of the same hub takes the whole volume at once.
  const auto all = hub.nextFrame(unpaced);
  ASSERT_TRUE(all.has_value());
  EXPECT_GT(all->payloadBytes, LinkEstimator::kInitialWindow + 16384);
  EXPECT_FALSE(hub.stats(unpaced).paced);
  // New lighting while it waits replaces what it lacks; its wake-up finds the window still full
  // (as a transport's would), and the ack wakes it again.
  hub.publish(test::movingLightFrame(probes, 20, 0.3f, rng).data(), nullptr);
  EXPECT_FALSE(hub.nextFrame(id).has_value());
  EXPECT_EQ(hub.stats(id).link.windowWaits, 2u);
  const int before = wakes;
  std::string why;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(hub.acknowledge(id, first->sequence, why)) << why;
  EXPECT_EQ(wakes, before + 1);
  const LinkStats link = hub.stats(id).link;
  EXPECT_GT(link.rateBytesPerSecond, 0.0);
  EXPECT_GE(link.minRttUs, 20000u);
  EXPECT_EQ(link.inFlightBytes, 0u);
  // Taken one window at a time, acking each, it ends with the newest volume, bit for bit.
  for (int i = 0; i < 100; ++i) {
    const auto f = hub.nextFrame(id);
    if (!f) break;
    bricksIn(*f, dec);
    ASSERT_TRUE(hub.acknowledge(id, f->sequence, why)) << why;
  }
  EXPECT_EQ(hub.stats(id).bricksBehind, 0u);
  const std::vector<float> want = hub.reconstruction().probes;
  EXPECT_EQ(0, std::memcmp(want.data(), dec.probes(), want.size() * sizeof(float)));
}

TEST(ProbeHub, StaleVersionsAreSkippedNotQueued) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(3);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  const uint64_t id = hub.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(hub.layout());
  bricksIn(*hub.nextFrame(id), dec);
  for (int f = 1; f <= 5; ++f) hub.publish(test::movingLightFrame(256, 10 * f, 0.0f, rng).data(), nullptr);
  const auto frame = hub.nextFrame(id);  // five versions behind: one keyframe per brick
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->keyframes, 4u);
  EXPECT_EQ(frame->deltas, 0u);
  bricksIn(*frame, dec);
  const std::vector<float> probes = hub.reconstruction().probes;
  EXPECT_EQ(0, std::memcmp(probes.data(), dec.probes(), probes.size() * sizeof(float)));
}

TEST(ProbeHub, ResumeSendsOnlyWhatIsLacking) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(4);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  const uint64_t first = hub.addSubscriber(0, 0, {}, nullptr);
  StreamDecoder dec(hub.layout());
  bricksIn(*hub.nextFrame(first), dec);
  hub.removeSubscriber(first);
  hub.publish(test::movingLightFrame(256, 10, 0.0f, rng).data(), nullptr);  // one version on
  std::vector<HeldBrick> held;
  for (uint32_t b = 0; b < 4; ++b) held.push_back({b, dec.brickVersion(b)});
  const uint64_t resumed = hub.addSubscriber(0, hub.epoch(), held, nullptr);
  const uint64_t fresh = hub.addSubscriber(0, 0, {}, nullptr);
  const auto r = hub.nextFrame(resumed), f = hub.nextFrame(fresh);
  ASSERT_TRUE(r && f);
  EXPECT_EQ(r->deltas, 4u);
  EXPECT_EQ(f->keyframes, 4u);
  EXPECT_LT(r->payload.size(), f->payload.size());
  bricksIn(*r, dec);
  // A wrong epoch voids the held versions.
  const uint64_t other = hub.addSubscriber(0, hub.epoch() + 1, held, nullptr);
  EXPECT_EQ(hub.nextFrame(other)->keyframes, 4u);
}


// A subscriber may ask for less than the stream carries: the hub encodes the volume it holds once
// more in that representation, shared by every subscriber that asks for it, as a stream of its own
// epoch. What such a subscriber decodes is bit for bit the hub's reconstruction of that stream, and
// with no dead-zone every active probe is exactly the stream's reconstruction through that codec.
TEST(ProbeHub, ACoarserRepresentationIsTranscodedOnceWithItsOwnEpoch) {
  ProbeHub hub(rowConfig());  // l2
  std::mt19937 rng(5);
  hub.publish(test::movingLightFrame(256, 0, 0.02f, rng).data(), nullptr);
  const uint64_t full = hub.addSubscriber(0, 0, {}, nullptr);
  struct Sub {
    Representation repr;
    uint64_t id;
    std::unique_ptr<StreamDecoder> dec;
    size_t bytes = 0;
  };
  std::vector<Sub> subs;
  for (Representation r : {Representation::Zh3, Representation::L1, Representation::Zh3Hallucinated, Representation::L1}) {
    const uint64_t id = hub.addSubscriber(0, 0, {}, nullptr, r);
    const bus::Volume v = hub.volumeFor(id);
    EXPECT_EQ(v.layout.repr, r);
    EXPECT_NE(v.epoch, hub.epoch());  // its versions are this hub's own
    subs.push_back({r, id, std::make_unique<StreamDecoder>(v.layout)});
  }
  EXPECT_EQ(hub.volumeFor(full).epoch, hub.epoch());
  EXPECT_EQ(hub.volumeFor(subs[1].id).epoch, hub.volumeFor(subs[3].id).epoch);  // one l1 stream
  StreamDecoder fullDec(hub.layout());
  size_t fullBytes = 0;
  for (int f = 1; f <= 6; ++f) {
    if (auto frame = hub.nextFrame(full)) {
      fullBytes += frame->payload.size();
      ASSERT_EQ(fullDec.apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
    }
    std::vector<uint8_t> l1Frames[2];
    for (size_t k = 0; k < subs.size(); ++k)
      if (auto frame = hub.nextFrame(subs[k].id)) {
        subs[k].bytes += frame->payload.size();
        ASSERT_EQ(subs[k].dec->apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok) << f << "," << k;
        if (subs[k].repr == Representation::L1) l1Frames[k == 1 ? 0 : 1] = frame->payload;
      }
    // Encoded once: the two l1 subscribers got the same sections (frames differ only in the header).
    ASSERT_EQ(l1Frames[0].size(), l1Frames[1].size());
    if (!l1Frames[0].empty()) {
      EXPECT_TRUE(std::equal(l1Frames[0].begin() + kFrameHeaderSize, l1Frames[0].end(),
                             l1Frames[1].begin() + kFrameHeaderSize));
    }
    hub.publish(test::movingLightFrame(256, f, 0.02f, rng).data(), nullptr);
  }
  for (const Sub& sub : subs) {
    while (auto frame = hub.nextFrame(sub.id)) {
      ASSERT_EQ(sub.dec->apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
    }
    const ProbeVolume held = hub.reconstruction(sub.repr);
    ASSERT_EQ(0, std::memcmp(held.probes.data(), sub.dec->probes(), held.probes.size() * sizeof(float)))
        << representationName(sub.repr);
    EXPECT_LT(sub.bytes, fullBytes) << representationName(sub.repr);
  }
  while (auto frame = hub.nextFrame(full)) {
    ASSERT_EQ(fullDec.apply(frame->payload.data(), frame->payload.size()), CodecStatus::Ok);
  }
  const ProbeVolume primary = hub.reconstruction();
  for (Representation r : {Representation::Zh3, Representation::L1}) {
    const ProbeVolume through = decodeAs(primary, r, /*zh3PerPixel=*/false), transcoded = hub.reconstruction(r);
    for (uint32_t p = 0; p < primary.count(); ++p) {
      if (!primary.active[p]) continue;
      for (int i = 0; i < kProbeFloats; ++i)
        ASSERT_EQ(transcoded.probes[p * kProbeFloats + i], through.probes[p * kProbeFloats + i])
            << representationName(r) << " probe " << p;
    }
  }
  EXPECT_THROW(hub.reconstruction(Representation::Fp16), std::invalid_argument);  // nobody asked for it
}

// Transcoding never invents what the stream lacks: only coarser representations are made, and a
// subscriber asking for a finer one is refused before it is added.
TEST(ProbeHub, AFinerRepresentationIsRefused) {
  EXPECT_TRUE(canTranscode(Representation::Zh3, Representation::Zh3));
  EXPECT_TRUE(canTranscode(Representation::Fp16, Representation::L2));
  EXPECT_TRUE(canTranscode(Representation::Zh3, Representation::Zh3Hallucinated));
  EXPECT_TRUE(canTranscode(Representation::Zh3Hallucinated, Representation::L1));
  EXPECT_FALSE(canTranscode(Representation::L1, Representation::Zh3Hallucinated));
  EXPECT_FALSE(canTranscode(Representation::Zh3Hallucinated, Representation::Zh3));
  EXPECT_FALSE(canTranscode(Representation::Zh3, Representation::L2));
  HubConfig c = rowConfig();
  c.layout.repr = Representation::Zh3;
  ProbeHub hub(c);
  std::mt19937 rng(6);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  EXPECT_THROW(hub.addSubscriber(0, 0, {}, nullptr, Representation::L2), std::invalid_argument);
  EXPECT_THROW(hub.addSubscriber(0, 0, {}, nullptr, Representation::Fp16), std::invalid_argument);
  EXPECT_EQ(hub.subscriberCount(), 0u);
  EXPECT_NO_THROW(hub.addSubscriber(0, 0, {}, nullptr, Representation::Zh3));
}

// A transcoded subscriber resumes with what it holds when it comes back with its stream's epoch;
// held versions under the primary's epoch (another stream's numbers) are void.
TEST(ProbeHub, ATranscodedSubscriberResumesOnlyUnderItsStreamsEpoch) {
  ProbeHub hub(rowConfig());
  std::mt19937 rng(7);
  hub.publish(test::movingLightFrame(256, 0, 0.0f, rng).data(), nullptr);
  const uint64_t first = hub.addSubscriber(0, 0, {}, nullptr, Representation::L1);
  const uint64_t epoch = hub.volumeFor(first).epoch;
  StreamDecoder dec(hub.volumeFor(first).layout);
  bricksIn(*hub.nextFrame(first), dec);
  hub.removeSubscriber(first);
  hub.publish(test::movingLightFrame(256, 10, 0.0f, rng).data(), nullptr);  // one version on
  std::vector<HeldBrick> held;
  for (uint32_t b = 0; b < 4; ++b) held.push_back({b, dec.brickVersion(b)});
  const uint64_t resumed = hub.addSubscriber(0, epoch, held, nullptr, Representation::L1);
  const auto r = hub.nextFrame(resumed);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->deltas, 4u);
  EXPECT_EQ(r->keyframes, 0u);
  bricksIn(*r, dec);
  EXPECT_EQ(0, std::memcmp(hub.reconstruction(Representation::L1).probes.data(), dec.probes(), 256 * kProbeFloats * sizeof(float)));
  const uint64_t wrongEpoch = hub.addSubscriber(0, hub.epoch(), held, nullptr, Representation::L1);
  EXPECT_EQ(hub.nextFrame(wrongEpoch)->keyframes, 4u);
}

}  // namespace
}  // namespace probecast::service
