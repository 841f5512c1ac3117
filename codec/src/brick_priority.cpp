// Brick priority: frusta, distance, change and age (CODEC.md §6).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "probecast/codec/priority.h"

namespace probecast {
namespace {

float at(const float m[16], int row, int col) { return m[col * 4 + row]; }

float distanceToBox(const float p[3], const float lo[3], const float hi[3]) {
  float d2 = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float d = std::max({lo[a] - p[a], 0.0f, p[a] - hi[a]});
    d2 += d * d;
  }
  return std::sqrt(d2);
}

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
    // The box corner farthest along the plane normal; if even it is outside, the box is.
    const float x = pl[0] >= 0 ? boxMax[0] : boxMin[0];
    const float y = pl[1] >= 0 ? boxMax[1] : boxMin[1];
    const float z = pl[2] >= 0 ? boxMax[2] : boxMin[2];
    if (pl[0] * x + pl[1] * y + pl[2] * z + pl[3] < 0.0f) return false;
  }
  return true;
}

void scoreBricks(const StreamLayout& layout, const GridBounds& bounds, std::span<const View> views,
                 std::span<const BrickCandidate> candidates, const PriorityParams& params, float* scores) {
  // Distances are measured in full-brick diagonals, the same scale for every brick.
  float diag2 = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const int n = layout.grid[a];
    const float cell = n > 1 ? (bounds.max[a] - bounds.min[a]) / static_cast<float>(n - 1) : 0.0f;
    diag2 += (cell * layout.brickDim) * (cell * layout.brickDim);
  }
  const float diag = std::max(std::sqrt(diag2), 1e-6f);
  for (uint32_t b = 0; b < candidates.size(); ++b) {
    const BrickCandidate& c = candidates[b];
    if (!(c.change > 0.0f) || c.bytes == 0) {
      scores[b] = 0.0f;
      continue;
    }
    float lo[3], hi[3];
    brickInfluenceBox(layout, bounds, b, lo, hi);
    bool visible = false;
    float nearest = views.empty() ? 0.0f : INFINITY;
    for (const View& v : views) {
      visible = visible || boxIntersectsFrustum(v.viewProj, lo, hi);
      nearest = std::min(nearest, distanceToBox(v.eye, lo, hi));
    }
    if (views.empty()) visible = true;
    const float distanceTerm = 1.0f / (1.0f + nearest / diag);
    const float changeTerm = std::max(c.change, params.minChange);
    const float ageTerm = 1.0f + params.ageWeight * static_cast<float>(c.ageFrames);
    scores[b] = (visible ? 1.0f : params.outOfViewWeight) * changeTerm * distanceTerm * ageTerm;
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
    if (used + candidates[b].bytes > budgetBytes) continue;
    used += candidates[b].bytes;
    out[chosen++] = b;
  }
  return chosen;
}

}  // namespace probecast
