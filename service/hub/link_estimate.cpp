#include "probecast/service/link_estimate.h"

#include <algorithm>
#include <cmath>

namespace probecast::service {
namespace {

double seconds(LinkEstimator::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Windowed extremes as monotonic queues: a sample that a newer, better one beats can never be the
// extreme again and is dropped; the front is the extreme; old ones leave the front, but the newest
// always stays (a link that has gone quiet keeps its last estimate).
template <typename Better>
void push(std::deque<std::pair<LinkEstimator::Time, double>>& q, LinkEstimator::Time t, double v, Better better) {
  while (!q.empty() && !better(q.back().second, v)) q.pop_back();
  q.emplace_back(t, v);
}

void expireBefore(std::deque<std::pair<LinkEstimator::Time, double>>& q, LinkEstimator::Time limit) {
  while (q.size() > 1 && q.front().first < limit) q.pop_front();
}

}  // namespace

void LinkEstimator::sent(uint32_t sequence, uint64_t bytes, bool appLimited, Time now) {
  if (unacked_.empty()) {  // nothing on the way: the next interval starts now, not at the last ack
    deliveredTime_ = now;
    firstSent_ = now;
  }
  if (!started_) {
    started_ = true;
    lastClean_ = now;
  }
  Sent s;
  s.alone = unacked_.empty();
  if (phase_ == Phase::Probing && !probeSent_) {
    probeSent_ = true;
    probeSequence_ = sequence;
  }
  s.sequence = sequence;
  s.bytes = bytes;
  s.deliveredAtSend = deliveredBytes_;
  s.deliveredTimeAtSend = deliveredTime_;
  s.firstSentAtSend = firstSent_;
  s.sentAt = now;
  s.appLimited = appLimited;
  unacked_.push_back(s);
  sentBytes_ += bytes;
  // A subscriber that never acks (or acks rarely) keeps a bounded record; what falls off counts as
  // delivered, so the window cannot stay shut on a record that is gone.
  while (unacked_.size() > 4096) {
    deliveredBytes_ += unacked_.front().bytes;
    unacked_.pop_front();
  }
}

void LinkEstimator::acked(uint32_t sequence, Time now) {
  if (unacked_.empty() || sequence < unacked_.front().sequence) return;
  Sent newest;
  bool found = false;
  while (!unacked_.empty() && unacked_.front().sequence <= sequence) {
    newest = unacked_.front();
    found = true;
    deliveredBytes_ += newest.bytes;
    unacked_.pop_front();
  }
  if (!found) return;
  if (newest.alone) lastClean_ = now;
  if (phase_ == Phase::Probing && probeSent_ && sequence >= probeSequence_) {
    phase_ = Phase::Normal;
    probeSent_ = false;
    lastClean_ = now;
  }
  deliveredTime_ = now;
  firstSent_ = newest.sentAt;
  // The delivery rate over the frame's flight: bytes acknowledged since it went out, over the
  // longer of the span they were sent in and the span their acks came back in (a burst sent at
  // once is not delivered at once; acks compressed on the way back do not speed up the link).
  const double sendSpan = seconds(newest.sentAt - newest.firstSentAtSend);
  const double ackSpan = seconds(now - newest.deliveredTimeAtSend);
  const double span = std::max(sendSpan, ackSpan);
  const double rtt = seconds(now - newest.sentAt);
  if (rtt > 0) {
    push(rtts_, now, rtt, [](double kept, double v) { return kept < v; });
    expireBefore(rtts_, now - std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kRttWindowSeconds)));
    minRttSeconds_ = rtts_.front().second;
  }
  if (span > 0) {
    const double sample = static_cast<double>(deliveredBytes_ - newest.deliveredAtSend) / span;
    // A sample taken while the sender had too little to send is a floor of the link's rate, not
    // its rate: it counts only where it raises the estimate.
    if (!newest.appLimited || sample >= rate()) push(rates_, now, sample, [](double kept, double v) { return kept > v; });
  }
  expire(now);
}

void LinkEstimator::expire(Time now) {
  const double window = std::max(kRateWindowSeconds, kRateRounds * minRttSeconds_);
  expireBefore(rates_, now - std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(window)));
}

double LinkEstimator::rate() const { return rates_.empty() ? 0.0 : rates_.front().second; }

uint64_t LinkEstimator::window() const {
  if (!measured()) return kInitialWindow;
  const double bdp = rate() * minRttSeconds_;
  const double w = kWindowGain * bdp;
  if (!(w < 0x1p63)) return UINT64_MAX / 2;
  return std::max<uint64_t>(kMinWindow, static_cast<uint64_t>(w));
}

uint64_t LinkEstimator::allowance(Time now) {
  if (phase_ == Phase::Normal && measured() && seconds(now - lastClean_) > kProbeIntervalSeconds)
    phase_ = Phase::Draining;
  if (phase_ == Phase::Draining) {
    if (inFlight() > 0) return 0;
    phase_ = Phase::Probing;
  }
  if (phase_ == Phase::Probing) return probeSent_ ? 0 : kProbeFrame;
  const uint64_t w = window(), f = inFlight();
  if (f >= w) return 0;
  return std::min(w - f, sentBytes_ == 0 ? kFirstFrame : std::max(kMinFrame, w / 4));
}

LinkStats LinkEstimator::stats() const {
  LinkStats s;
  s.rateBytesPerSecond = rate();
  s.minRttUs = static_cast<uint32_t>(std::min(4.0e9, std::round(minRttSeconds_ * 1e6)));
  s.windowBytes = window();
  s.inFlightBytes = inFlight();
  s.windowWaits = waits_;
  return s;
}

}  // namespace probecast::service
