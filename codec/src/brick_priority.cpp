// Brick priority: frusta, distance, change and age (docs/CODEC.md §6).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <vector>

#include "probecast/codec/priority.h"

namespace probecast {
namespace {

float at(const float m[16], int row, int col) { return m[col * 4 + row]; }

// In double: a finite eye 2e19 m away squares past FLT_MAX, and an infinite distance would score
// every brick 0 and silence the stream.
double distanceToBox(const float p[3], const float lo[3], const float hi[3]) {
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({double(lo[a]) - p[a], 0.0, double(p[a]) - hi[a]});
    d2 += d * d;
  }
  return std::sqrt(d2);
}

// The distance term never falls below this: an eye farther than ~1e20 brick diagonals is, to
// float precision, equally far from every brick, so the floor loses no ordering, and with the
// other terms' floors (minChange, outOfViewWeight) a score stays a normal positive float.
constexpr double kMinDistanceTerm = 1e-20;

}  // namespace

void brickInfluenceBox(const StreamLayout& layout, const GridBounds& bounds, uint32_t brick, float boxMin[3],
                       float boxMax[3]) {
  uint32_t begin[3], size[3];
  brickProbeRange(layout, brick, begin, size);
  for (int a = 0; a < 3; ++a) {
    const int n = layout.grid[a];
    const float cell = n > 1 ? (bounds.max[a] - bounds.min[a]) / static_cast<float>(n - 1) : 0.0f;
    const float lo = bounds.min[a] + cell * static_cast<float>(begin[a]);
    const float hi = bounds.min[a] + cell * static_cast<float>(begin[a] + size[a] - 1);
    boxMin[a] = std::max(bounds.min[a], lo - cell);
    boxMax[a] = std::min(bounds.max[a], hi + cell);
  }
}

bool boxIntersectsFrustum(const float m[16], const float boxMin[3], const float boxMax[3]) {
  // Planes (Gribb-Hartmann) for Vulkan clip space: -w<=x<=w, -w<=y<=w, 0<=z<=w.
  float planes[6][4];
  for (int c = 0; c < 4; ++c) {
    const float r0 = at(m, 0, c), r1 = at(m, 1, c), r2 = at(m, 2, c), r3 = at(m, 3, c);
    planes[0][c] = r3 + r0;
    planes[1][c] = r3 - r0;
    planes[2][c] = r3 + r1;
    planes[3][c] = r3 - r1;
    planes[4][c] = r2;
    planes[5][c] = r3 - r2;
  }
  for (const auto& pl : planes) {
    // The box corner farthest along the plane normal; if even it is outside, the box is. In
    // double, so huge finite matrices and boxes cannot overflow to inf - inf.
    const double x = pl[0] >= 0 ? boxMax[0] : boxMin[0];
    const double y = pl[1] >= 0 ? boxMax[1] : boxMin[1];
    const double z = pl[2] >= 0 ? boxMax[2] : boxMin[2];
    if (double(pl[0]) * x + double(pl[1]) * y + double(pl[2]) * z + double(pl[3]) < 0.0) return false;
  }
  return true;
}

void scoreBricks(const StreamLayout& layout, const GridBounds& bounds, std::span<const View> views,
                 std::span<const BrickCandidate> candidates, const PriorityParams& params, float* scores) {
  // Distances are measured in full-brick diagonals, the same scale for every brick. Scores are
  // computed in double and are finite and positive for any finite view (a view a light-year or
  // 1e30 m away still receives every brick, nearest first as far as float can tell).
  double diag2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const int n = layout.grid[a];
    const double cell = n > 1 ? (double(bounds.max[a]) - bounds.min[a]) / (n - 1) : 0.0;
    diag2 += (cell * layout.brickDim) * (cell * layout.brickDim);
  }
  const double diag = std::max(std::sqrt(diag2), 1e-6);
  for (uint32_t b = 0; b < candidates.size(); ++b) {
    const BrickCandidate& c = candidates[b];
    if (!(c.change > 0.0f) || c.bytes == 0) {
      scores[b] = 0.0f;
      continue;
    }
    float lo[3], hi[3];
    brickInfluenceBox(layout, bounds, b, lo, hi);
    bool visible = false;
    double nearest = views.empty() ? 0.0 : INFINITY;
    for (const View& v : views) {
      visible = visible || boxIntersectsFrustum(v.viewProj, lo, hi);
      nearest = std::min(nearest, distanceToBox(v.eye, lo, hi));
    }
    if (views.empty()) visible = true;
    double distanceTerm = 1.0 / (1.0 + nearest / diag);
    if (!(distanceTerm >= kMinDistanceTerm)) distanceTerm = kMinDistanceTerm;  // NaN too (a non-finite eye)
    const double changeTerm = std::max(double(c.change), double(params.minChange));
    const double ageTerm = 1.0 + double(params.ageWeight) * c.ageFrames;
    const double score = (visible ? 1.0 : double(params.outOfViewWeight)) * changeTerm * distanceTerm * ageTerm;
    // A brick out of view that weighs nothing (or a non-positive age term) stays at 0; any other
    // score is a normal positive float.
    if (!(score > 0.0))
      scores[b] = 0.0f;
    else
      scores[b] = score >= FLT_MAX ? FLT_MAX : score >= FLT_MIN ? static_cast<float>(score) : FLT_MIN;
  }
}

size_t selectBricks(std::span<const float> scores, std::span<const BrickCandidate> candidates, uint64_t budgetBytes,
                    uint32_t* out) {
  std::vector<uint32_t> order(scores.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return scores[a] > scores[b]; });
  size_t chosen = 0;
  uint64_t used = 0;
  for (uint32_t b : order) {
    if (!(scores[b] > 0.0f)) break;
    if (candidates[b].bytes > budgetBytes - used) continue;  // used <= budgetBytes: cannot wrap
    used += candidates[b].bytes;
    out[chosen++] = b;
  }
  return chosen;
}

}  // namespace probecast
