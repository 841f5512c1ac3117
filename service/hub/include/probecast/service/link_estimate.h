// What one subscriber's acks say about the link it is on: how fast bytes reach it and how long
// a frame takes to come back acknowledged, measured per frame in the manner of BBR's delivery
// rate estimation (Cardwell et al., "BBR: Congestion-Based Congestion Control", 2016). From those
// two the hub keeps at most a window of unacknowledged bytes on the way to the subscriber, so
// that what waits is chosen by priority in the hub (newest versions, best bricks first) instead
// of queueing in socket buffers and on the link, where nothing can overtake it.
//
// Transport-free and clock-free: every call takes the time, so tests drive it with their own.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>

namespace probecast::service {

struct LinkStats {
  double rateBytesPerSecond = 0;  // delivery rate, windowed maximum (0 until measured)
  uint32_t minRttUs = 0;          // frame handed out → its ack back, windowed minimum (0 until measured)
  uint64_t windowBytes = 0;       // unacknowledged bytes allowed on the way
  uint64_t inFlightBytes = 0;     // unacknowledged bytes on the way now
  uint32_t windowWaits = 0;       // times a frame waited for the window to open
};

class LinkEstimator {
 public:
  using Clock = std::chrono::steady_clock;
  using Time = Clock::time_point;

  // Before the first measurement (what a TCP connection's initial window does for one round trip).
  static constexpr uint64_t kInitialWindow = 64 * 1024;
  // Never below this: a window of a few bytes would stall on every brick.
  static constexpr uint64_t kMinWindow = 16 * 1024;
  // A frame carries at most a quarter of the window (and at least this much): frames are the
  // packets of this estimate, and several must be on the way at once for their acks to measure the
  // link's rate rather than one frame's round trip.
  static constexpr uint64_t kMinFrame = 8 * 1024;
  // The first frame carries at most this much. A fresh connection's first flight (TCP's initial
  // window: 10 segments, about 14 kB, RFC 6928) also carries the volume description and HTTP/2's
  // framing; a first frame that spills past it arrives a round trip later (a quarter of a second
  // on a mobile link), and with it the first lighting after a resume.
  static constexpr uint64_t kFirstFrame = 8 * 1024;
  // The round trip's minimum is only seen with nothing queued. A stream that always has more to send
  // keeps the window's standing queue, so every kProbeIntervalSeconds without a frame that went out
  // onto an empty link, the hub lets everything on the way arrive and sends one frame of at most
  // kProbeFrame alone (BBR's ProbeRTT).
  static constexpr uint64_t kProbeFrame = 4 * 1024;
  static constexpr double kProbeIntervalSeconds = 5.0;
  // The window is this many bandwidth-delay products: the bottleneck stays busy while an ack is on
  // its way back, and at most half a product's worth queues behind it. (BBR uses 2; over a 1 Mbit/s,
  // 100 ms link 1.5 halved the stream's p99 latency, 1.65 → 0.75 s, for 13 % fewer bytes
  // delivered: bench/wan_bench.py --test.)
  static constexpr double kWindowGain = 1.5;
  // Rate samples count for this long (at least kRateRounds round trips); the round trip's
  // minimum for kRttWindow.
  static constexpr double kRateWindowSeconds = 2.0;
  static constexpr int kRateRounds = 10;
  static constexpr double kRttWindowSeconds = 10.0;

  // A frame of `bytes` went out at `now`. appLimited: the sender had nothing more to send after
  // it, so a low rate measured over it says nothing about the link.
  void sent(uint32_t sequence, uint64_t bytes, bool appLimited, Time now);
  // The subscriber applied every frame up to `sequence` (a cumulative ack; one never sent or
  // already acknowledged changes nothing).
  void acked(uint32_t sequence, Time now);
  // A frame could not go because the window was full.
  void waited() { ++waits_; }

  bool measured() const { return !rates_.empty() && minRttSeconds_ > 0; }
  uint64_t inFlight() const { return sentBytes_ - deliveredBytes_; }
  uint64_t window() const;
  // Bytes the next frame may carry now: within the window and the frame's share of it (0 when it is
  // full, or while the link drains for a round-trip probe).
  uint64_t allowance(Time now);
  LinkStats stats() const;

 private:
  struct Sent {
    uint32_t sequence = 0;
    uint64_t bytes = 0;
    uint64_t deliveredAtSend = 0;  // bytes acknowledged when it went out
    Time deliveredTimeAtSend;      // when that much had been acknowledged
    Time firstSentAtSend;          // when the newest frame acknowledged then had gone out
    Time sentAt;
    bool appLimited = false;
    bool alone = false;  // nothing else was on the way: its round trip saw no queue of ours
  };
  enum class Phase { Normal, Draining, Probing };
  double rate() const;
  void expire(Time now);

  std::deque<Sent> unacked_;
  uint64_t sentBytes_ = 0, deliveredBytes_ = 0;
  Time deliveredTime_{}, firstSent_{};
  std::deque<std::pair<Time, double>> rates_;  // samples (when, bytes per second), kept while they may be the maximum
  std::deque<std::pair<Time, double>> rtts_;   // samples (when, seconds), kept while they may be the minimum
  double minRttSeconds_ = 0;
  uint32_t waits_ = 0;
  Phase phase_ = Phase::Normal;
  bool probeSent_ = false;
  uint32_t probeSequence_ = 0;
  Time lastClean_{};  // when a frame sent alone was last acknowledged (or the first frame went out)
  bool started_ = false;
};

}  // namespace probecast::service
