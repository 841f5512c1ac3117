// The session layer's pieces: statistics, representation names, volume conversions, the probe
// producer's loop (no GPU, no network) and the child process the stream benchmark serves from.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <thread>

#include "probecast/session/probe_producer.h"
#include "probecast/session/representation.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "probecast/testing/child_process.h"

namespace probecast::session {
namespace {

TEST(SessionStats, MedianIsTheUpperMiddleSampleAndPercentileTheNearestRank) {
  EXPECT_EQ(median({3.0, 1.0, 2.0, 4.0}), 3.0);  // sorted 1 2 3 4: v[4 / 2]
  EXPECT_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(medianMidpoint({3.0, 1.0, 2.0, 4.0}), 2.5);
  std::vector<int> hundred;
  for (int i = 1; i <= 100; ++i) hundred.push_back(i);
  EXPECT_EQ(percentile(hundred, 0.99), 99.0);  // rank round(0.99 · 99) = 98
  EXPECT_EQ(percentile(hundred, 0.0), 1.0);
  EXPECT_EQ(percentile(hundred, 1.0), 100.0);
}

TEST(SessionRepresentation, UnknownNamesGetOneMessage) {
  EXPECT_EQ(checkRepresentation("zh3"), "");
  EXPECT_EQ(checkRepresentation("l3"), "unknown representation 'l3' (l1, zh3h, zh3, l2, fp16)");
  EXPECT_EQ(checkRepresentation("float", true), "");
  EXPECT_NE(checkRepresentation("float"), "");
  EXPECT_EQ(parseRepresentationOrThrow("l2"), Representation::L2);
  EXPECT_THROW(parseRepresentationOrThrow("l3"), std::runtime_error);
}

TEST(SessionVolumes, HubConfigCarriesGridBoundsAndEncoderSettings) {
  const ProbeGrid g = unitGrid({8, 4, 2});
  const service::HubConfig hc = service::hubConfigFor(g, Representation::Zh3, 4, 2);
  EXPECT_EQ(hc.layout.grid[0], 8);
  EXPECT_EQ(hc.layout.grid[2], 2);
  EXPECT_EQ(hc.layout.brickDim, 4);
  EXPECT_EQ(hc.layout.repr, Representation::Zh3);
  EXPECT_EQ(hc.encoder.deadzone, 2);
  EXPECT_EQ(hc.bounds.max[0], 7.0f);
  EXPECT_EQ(hc.bounds.max[1], 3.0f);
}

TEST(SessionVolumes, AreaLightOptionsAndTheStatedRuleAreOneDecision) {
  scene::AreaLightOptions o;
  EXPECT_FALSE(areaLightRuleOf(o).on());  // off: the probes hold every emitter
  o.enabled = true;
  o.minPowerFraction = 0.125f;
  const AreaLightRule rule = areaLightRuleOf(o);
  EXPECT_EQ(rule, (AreaLightRule{kAreaLightRuleVersion, 0.125f}));
  const scene::AreaLightOptions back = areaLightOptionsOf(rule);
  EXPECT_TRUE(back.enabled);
  EXPECT_EQ(back.minPowerFraction, 0.125f);
  EXPECT_EQ(back.maxLights, o.maxLights);
  EXPECT_EQ(back.maxTriangles, o.maxTriangles);
  EXPECT_FALSE(areaLightOptionsOf({}).enabled);
  // Caps a viewer could not know, a threshold that is no share, and unknown rules are refused.
  scene::AreaLightOptions caps = o;
  caps.maxLights = 3;
  EXPECT_THROW(areaLightRuleOf(caps), std::invalid_argument);
  o.minPowerFraction = std::nanf("");
  EXPECT_THROW(areaLightRuleOf(o), std::invalid_argument);
  EXPECT_THROW(areaLightOptionsOf({9, 0.1f}), std::invalid_argument);
  // A viewer follows the rule, or is refused when it asks for the opposite or another threshold.
  EXPECT_TRUE(followAreaLightRule(rule, std::nullopt, std::nullopt, "x").enabled);
  EXPECT_TRUE(followAreaLightRule(rule, true, 0.125f, "x").enabled);
  EXPECT_FALSE(followAreaLightRule({}, false, std::nullopt, "x").enabled);
  const auto refusal = [](const AreaLightRule& r, std::optional<bool> wanted, std::optional<float> min) {
    try {
      followAreaLightRule(r, wanted, min, "the server");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal(rule, false, std::nullopt).find("would be lost"), std::string::npos);
  EXPECT_NE(refusal({}, true, std::nullopt).find("twice"), std::string::npos);
  EXPECT_NE(refusal(rule, std::nullopt, 0.5f).find("were made with 0.125"), std::string::npos);
}

TEST(SessionVolumes, AnL1OnlyHolderIsComparedOnItsTwelveFloats) {
  ProbeVolume server = makeProbeVolume(unitGrid({2, 1, 1}));
  std::fill(server.probes.begin(), server.probes.end(), 1.0f);
  ProbeVolume held = server;
  held.probes[20] = 0.0f;  // an L2 coefficient
  EXPECT_FALSE(holdsVolume(held, server));
  held.zh3PerPixel = true;
  EXPECT_TRUE(holdsVolume(held, server));
  held.probes[3] = 0.0f;  // an L1 coefficient
  EXPECT_FALSE(holdsVolume(held, server));
}

service::HubConfig smallHub() { return service::hubConfigFor(unitGrid({4, 4, 4}), Representation::Zh3, 4, 0); }

void constantFrame(uint32_t frame, std::vector<float>& probes) {
  probes.assign(64 * kProbeFloats, 0.0f);
  for (size_t i = 0; i < probes.size(); i += kProbeFloats) probes[i] = 1.0f + static_cast<float>(frame);
}

TEST(SessionProducer, GeneratedFramesArePublishedWhileMovingAndHeldOtherwise) {
  ProbeProducer producer(smallHub());
  producer.generate(constantFrame);
  for (int k = 0; k < 3; ++k) producer.step();
  EXPECT_EQ(producer.stats().updates, 3u);
  std::vector<float> probes = producer.hub().reconstruction().probes;
  ASSERT_EQ(probes.size(), 64u * kProbeFloats);
  const float held = probes[0];
  producer.setMoving(false);
  producer.step();
  EXPECT_EQ(producer.stats().updates, 3u);
  probes = producer.hub().reconstruction().probes;
  EXPECT_EQ(probes[0], held);
}

TEST(SessionProducer, FixedRateLoopEndsAfterItsSeconds) {
  ProbeProducer producer(smallHub());
  producer.generate(constantFrame);
  Pacing pacing;
  pacing.mode = Pacing::Mode::FixedRate;
  pacing.hz = 50.0;
  pacing.seconds = 0.3;
  producer.run(pacing);
  const uint32_t updates = producer.stats().updates;
  EXPECT_GE(updates, 10u);  // 15 at 50 Hz, allowing for a loaded machine
  EXPECT_LE(updates, 16u);
  EXPECT_FALSE(producer.running());
}

TEST(SessionProducer, ThreadLoopStopsOnRequest) {
  ProbeProducer producer(smallHub());
  producer.generate(constantFrame);
  Pacing pacing;
  pacing.mode = Pacing::Mode::FixedSleep;
  pacing.sleepMs = 5.0;
  producer.start(pacing);
  while (producer.stats().updates < 3) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(producer.running());
  producer.stop();
  EXPECT_FALSE(producer.running());
  EXPECT_EQ(producer.error(), "");
}

TEST(SessionChildProcess, RunsOnlyAfterGoAndPassesLinesAndStatus) {
  testing::ChildProcess child([](const testing::ChildProcess::Say& say) {
    say("port 1234");
    say("report done");
    return 3;
  });
  child.go();
  std::string line;
  ASSERT_TRUE(child.readLine(line));
  EXPECT_EQ(line, "port 1234");
  ASSERT_TRUE(child.readLine(line));
  EXPECT_EQ(line, "report done");
  EXPECT_FALSE(child.readLine(line));
  EXPECT_EQ(child.wait(), 3);
}

TEST(SessionChildProcess, TakesLinesOfAnyLengthBothWays) {
  const std::string longLine(100000, 'x');  // a histogram or a list of samples is long
  testing::ChildProcess child([&longLine](const testing::ChildProcess::Say& say,
                                          const testing::ChildProcess::Hear& hear) {
    std::string line;
    while (hear(line)) {
      if (line == "quit") return 5;
      say(line == longLine ? "long ok" : "echo " + line);
    }
    return 1;  // the parent went away without "quit"
  });
  child.go();
  std::string line;
  ASSERT_TRUE(child.tell("ping"));
  ASSERT_TRUE(child.readLine(line));
  EXPECT_EQ(line, "echo ping");
  ASSERT_TRUE(child.tell(longLine));
  ASSERT_TRUE(child.readLine(line));
  EXPECT_EQ(line, "long ok");
  ASSERT_TRUE(child.tell("quit"));
  EXPECT_FALSE(child.readLine(line));
  EXPECT_EQ(child.wait(), 5);
  EXPECT_FALSE(child.tell("after the end"));
}

TEST(SessionChildProcess, ALongLineFromTheChildArrivesWhole) {
  testing::ChildProcess child([](const testing::ChildProcess::Say& say) {
    say(std::string(5000, 'y'));
    return 0;
  });
  child.go();
  std::string line;
  ASSERT_TRUE(child.readLine(line));
  EXPECT_EQ(line, std::string(5000, 'y'));
  EXPECT_FALSE(child.readLine(line));
  EXPECT_EQ(child.wait(), 0);
}

TEST(SessionChildProcess, AChildDroppedBeforeGoEndsWithoutRunning) {
  auto first = std::make_unique<testing::ChildProcess>([](const testing::ChildProcess::Say&) { return 7; });
  testing::ChildProcess second([](const testing::ChildProcess::Say&) { return 0; });  // holds no copy of first's pipes
  first.reset();  // would hang if the second child kept first's "go" pipe open
  second.go();
  EXPECT_EQ(second.wait(), 0);
}

}  // namespace
}  // namespace probecast::session
