// The link estimator, driven by a simulated link: a bottleneck of a known rate and delay that
// delivers frames in order, acked at once on arrival. Its estimates must find the link, and the
// window it derives must keep the bottleneck's queue short.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "probecast/service/link_estimate.h"

namespace probecast::service {
namespace {

using Time = LinkEstimator::Time;
using namespace std::chrono_literals;

Time at(double seconds) { return Time{} + std::chrono::duration_cast<LinkEstimator::Clock::duration>(std::chrono::duration<double>(seconds)); }

// A sender that always has `frameBytes` frames to send (never application-limited) through a link
// of `rate` bytes/s and `oneWay` seconds each way, within the estimator's window. Returns the
// longest time a frame spent queued at the bottleneck.
struct SimResult {
  double maxQueueSeconds = 0;
  double deliveredBytesPerSecond = 0;
};

// From `changeAt` on, the link's rate is `rateAfter` (0: unchanged). The queue is measured after
// `settle` seconds (the initial window's burst is the first round trip's).
SimResult simulate(LinkEstimator& link, double rate, double oneWay, uint64_t frameBytes, double seconds,
                   double rateAfter = 0, double changeAt = 0, double settle = 2.0) {
  struct InFlight {
    uint32_t sequence;
    double ackAt;
  };
  std::vector<InFlight> flight;
  double now = 0, linkFree = 0, maxQueue = 0;
  uint64_t delivered = 0;
  uint32_t sequence = 0;
  const double step = 0.001;
  while (now < seconds) {
    // Acks that have come back by now, oldest first.
    while (!flight.empty() && flight.front().ackAt <= now) {
      link.acked(flight.front().sequence, at(flight.front().ackAt));
      flight.erase(flight.begin());
    }
    // Send while the window allows (a frame always goes when nothing is on the way).
    for (;;) {
      const uint64_t allowed = link.allowance(at(now));  // first: it may start a round-trip probe
      if (link.inFlight() != 0 && allowed < frameBytes) break;
      const double start = std::max(now, linkFree);
      if (now >= settle) maxQueue = std::max(maxQueue, start - now);
      linkFree = start + static_cast<double>(frameBytes) / (rateAfter > 0 && now >= changeAt ? rateAfter : rate);
      if (linkFree + oneWay <= seconds) delivered += frameBytes;
      link.sent(++sequence, frameBytes, false, at(now));
      flight.push_back({sequence, linkFree + 2 * oneWay});
    }
    now += step;
  }
  return {maxQueue, static_cast<double>(delivered) / seconds};
}

TEST(LinkEstimator, StartsWithTheInitialWindowAndNoEstimate) {
  LinkEstimator link;
  EXPECT_FALSE(link.measured());
  EXPECT_EQ(link.window(), LinkEstimator::kInitialWindow);
  // The first frame carries what fits a fresh connection's first flight, the next ones at most a
  // quarter of the window.
  EXPECT_EQ(link.allowance(at(0)), LinkEstimator::kFirstFrame);
  link.sent(1, 1000, false, at(0));
  EXPECT_EQ(link.inFlight(), 1000u);
  EXPECT_EQ(link.allowance(at(0)), LinkEstimator::kInitialWindow / 4);
}

TEST(LinkEstimator, FindsTheRateAndRoundTripOfASlowLink) {
  // 1 Mbit/s (125 kB/s), 125 ms each way.
  LinkEstimator link;
  const SimResult r = simulate(link, 125000.0, 0.125, 4000, 10.0);
  const LinkStats s = link.stats();
  EXPECT_NEAR(s.rateBytesPerSecond, 125000.0, 125000.0 * 0.1);
  EXPECT_GE(s.minRttUs, 250000u);
  EXPECT_LT(s.minRttUs, 250000u + 2 * 32000u + 2000u);  // one frame's serialisation and the simulation's step
  // The window holds the link busy: nearly all of its rate is used ...
  EXPECT_GT(r.deliveredBytesPerSecond, 125000.0 * 0.85);
  // ... and what queues at the bottleneck is at most one window (1.5 bandwidth-delay products, the
  // burst after a round-trip probe has drained the link), not the seconds an unbounded sender
  // queues (below).
  EXPECT_LT(r.maxQueueSeconds, LinkEstimator::kWindowGain * 0.282 + 0.01);
}

TEST(LinkEstimator, GrowsQuicklyOnAFastLink) {
  // 50 Mbit/s (6.25 MB/s), 10 ms each way: from the initial window, about a doubling per round trip.
  LinkEstimator link;
  const SimResult r = simulate(link, 6.25e6, 0.010, 16000, 2.0);
  EXPECT_NEAR(link.stats().rateBytesPerSecond, 6.25e6, 6.25e6 * 0.1);
  EXPECT_GT(r.deliveredBytesPerSecond, 6.25e6 * 0.8);
  EXPECT_LT(r.maxQueueSeconds, 0.05);
}

TEST(LinkEstimator, WithoutAWindowTheSameSenderQueuesWithoutBound) {
  // What the window prevents: the same sender with everything allowed (an estimator that is never
  // acked keeps the initial window, so here the sender simply ignores it) queues seconds of data.
  double linkFree = 0, maxQueue = 0;
  for (double now = 0; now < 5.0; now += 0.01) {  // 400 kB/s offered to a 125 kB/s link
    const double start = std::max(now, linkFree);
    maxQueue = std::max(maxQueue, start - now);
    linkFree = start + 4000.0 / 125000.0;
  }
  EXPECT_GT(maxQueue, 3.0);
}

TEST(LinkEstimator, ApplicationLimitedSamplesDoNotLowerTheEstimate) {
  LinkEstimator link;
  simulate(link, 125000.0, 0.05, 4000, 5.0);
  const double measured = link.stats().rateBytesPerSecond;
  ASSERT_GT(measured, 100000.0);
  // Then a trickle: one small frame every 200 ms, each acked after the round trip. Its samples are
  // far below the link's rate, but the sender had nothing more to send.
  double now = 5.0;
  for (uint32_t seq = 100000; seq < 100040; ++seq) {
    link.sent(seq, 500, true, at(now));
    link.acked(seq, at(now + 0.1));
    now += 0.2;
  }
  EXPECT_GE(link.stats().rateBytesPerSecond, measured * 0.999);
}

TEST(LinkEstimator, ALinkThatSlowsDownIsFoundWithinTheRateWindow) {
  LinkEstimator before;
  simulate(before, 625000.0, 0.05, 8000, 4.0);
  EXPECT_NEAR(before.stats().rateBytesPerSecond, 625000.0, 625000.0 * 0.1);
  // The same link dropping to a fifth of its rate at 4 s: the old samples leave the window and the
  // estimate follows; the queue that built in the meantime drains.
  LinkEstimator link;
  const SimResult r = simulate(link, 625000.0, 0.05, 8000, 12.0, 125000.0, 4.0);
  // (Within a quarter: the round trip's minimum is still the fast link's, and a window of 1.5 of
  // its product leaves the slow link a little idle between frames.)
  EXPECT_NEAR(link.stats().rateBytesPerSecond, 125000.0, 125000.0 * 0.25);
  EXPECT_LT(r.maxQueueSeconds, 2.0);
}

TEST(LinkEstimator, CumulativeAcksAndUnknownSequencesAreSafe) {
  LinkEstimator link;
  link.sent(1, 1000, false, at(0.0));
  link.sent(2, 1000, false, at(0.01));
  link.sent(3, 1000, false, at(0.02));
  link.acked(7, at(0.2));  // never sent: everything up to it is acknowledged, nothing more
  EXPECT_EQ(link.inFlight(), 0u);
  link.acked(2, at(0.3));  // already acknowledged
  EXPECT_EQ(link.inFlight(), 0u);
  link.sent(4, 5000, false, at(0.4));
  link.acked(4, at(0.5));
  EXPECT_TRUE(link.measured());
  EXPECT_EQ(link.inFlight(), 0u);
  EXPECT_GE(link.window(), LinkEstimator::kMinWindow);
}

TEST(LinkEstimator, ASubscriberThatNeverAcksKeepsABoundedRecord) {
  LinkEstimator link;
  for (uint32_t s = 1; s <= 10000; ++s) link.sent(s, 10, true, at(s * 0.001));
  EXPECT_LE(link.inFlight(), 4096u * 10u);
}

}  // namespace
}  // namespace probecast::service
