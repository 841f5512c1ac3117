// A histogram of durations in microseconds with bounded relative error, cheap to record into and
// to merge, with a one-line text form so processes can pass it to each other. Buckets are
// log-linear: exact below 32 µs, then 32 buckets per power of two (each at most 1/32 of its
// lower edge wide), so a percentile read back is within about 1.6% of the true sample.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <sstream>
#include <string>

namespace probecast::service {

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 5;
  static constexpr uint32_t kSub = 1u << kSubBits;
  static constexpr size_t kBuckets = (64 - kSubBits + 1) * kSub;

  void record(uint64_t us) {
    ++counts_[bucketOf(us)];
    ++count_;
    max_ = std::max(max_, us);
  }
  void merge(const LatencyHistogram& other) {
    for (size_t i = 0; i < kBuckets; ++i) counts_[i] += other.counts_[i];
    count_ += other.count_;
    max_ = std::max(max_, other.max_);
  }
  void clear() { *this = LatencyHistogram(); }

  uint64_t count() const { return count_; }
  uint64_t maxUs() const { return max_; }
  // The sample at nearest rank round(p · (count − 1)) (as session::percentile), read as the middle
  // of its bucket and never above the largest sample; 0 when empty.
  double percentileUs(double p) const {
    if (count_ == 0) return 0.0;
    const uint64_t rank = static_cast<uint64_t>(std::clamp(p, 0.0, 1.0) * static_cast<double>(count_ - 1) + 0.5);
    uint64_t seen = 0;
    for (size_t i = 0; i < kBuckets; ++i) {
      seen += counts_[i];
      if (seen > rank) {
        const double mid = static_cast<double>(lowerEdge(i)) + 0.5 * static_cast<double>(width(i) - 1);
        return std::min(mid, static_cast<double>(max_));
      }
    }
    return static_cast<double>(max_);
  }
  double percentileMs(double p) const { return percentileUs(p) / 1000.0; }

  // "COUNT MAX i:n i:n ..." over the nonzero buckets.
  std::string toText() const {
    std::ostringstream out;
    out << count_ << ' ' << max_;
    for (size_t i = 0; i < kBuckets; ++i)
      if (counts_[i]) out << ' ' << i << ':' << counts_[i];
    return out.str();
  }
  // Parses toText's form; false (and `out` untouched) when it is not that.
  static bool fromText(const std::string& text, LatencyHistogram& out) {
    std::istringstream in(text);
    LatencyHistogram h;
    if (!(in >> h.count_ >> h.max_)) return false;
    uint64_t total = 0;
    for (std::string item; in >> item;) {
      const size_t colon = item.find(':');
      if (colon == std::string::npos) return false;
      try {
        size_t used = 0;
        const unsigned long long i = std::stoull(item.substr(0, colon), &used);
        if (used != colon || i >= kBuckets) return false;
        const unsigned long long n = std::stoull(item.substr(colon + 1), &used);
        if (used != item.size() - colon - 1) return false;
        h.counts_[i] += n;
        total += n;
      } catch (const std::exception&) {
        return false;
      }
    }
    if (total != h.count_) return false;
    out = h;
    return true;
  }

  static size_t bucketOf(uint64_t us) {
    if (us < kSub) return static_cast<size_t>(us);
    const int e = 63 - std::countl_zero(us);  // us in [2^e, 2^(e+1)), e >= kSubBits
    return static_cast<size_t>(e - kSubBits + 1) * kSub + ((us >> (e - kSubBits)) & (kSub - 1));
  }
  static uint64_t lowerEdge(size_t bucket) {
    if (bucket < kSub) return bucket;
    const int e = static_cast<int>(bucket / kSub) + kSubBits - 1;
    return (uint64_t{kSub} + bucket % kSub) << (e - kSubBits);
  }
  static uint64_t width(size_t bucket) {
    return bucket < kSub ? 1 : uint64_t{1} << (static_cast<int>(bucket / kSub) - 1);
  }

 private:
  std::array<uint64_t, kBuckets> counts_{};
  uint64_t count_ = 0;
  uint64_t max_ = 0;
};

}  // namespace probecast::service
