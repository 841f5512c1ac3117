// Order statistics of measured samples (times, rates, latencies), one definition for every tool.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace probecast::session {

// The sample at rank round(p · (n − 1)) of the sorted samples (nearest rank); 0 when empty.
template <typename T>
double percentile(std::vector<T> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5));
  return static_cast<double>(v[i]);
}

// The upper middle sample (v[n / 2] of the sorted samples, = percentile 0.5); 0 when empty.
inline double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

// The median with an even count taken as the mean of the two middle samples; 0 when empty.
inline double medianMidpoint(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace probecast::session
