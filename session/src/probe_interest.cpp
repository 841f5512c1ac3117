// Probes inside the subscribers' views (probe_interest.h).
#include "probecast/session/probe_interest.h"

#include <algorithm>
#include <cmath>

namespace probecast::session {
namespace {

bool finiteView(const View& v) {
  return std::all_of(std::begin(v.viewProj), std::end(v.viewProj), [](float f) { return std::isfinite(f); });
}

}  // namespace

std::vector<float> probeViewWeights(const ProbeGrid& grid, const std::vector<float>& offsets, std::span<const View> views) {
  std::vector<const View*> usable;
  for (const View& v : views)
    if (finiteView(v)) usable.push_back(&v);
  if (views.empty()) return {};
  const uint32_t count = grid.count();
  const bool moved = offsets.size() == static_cast<size_t>(count) * 3;
  float cell[3];
  for (int a = 0; a < 3; ++a) cell[a] = probeCellSize(grid, a);
  std::vector<float> weights(count, 0.0f);
  for (uint32_t p = 0; p < count; ++p) {
    float centre[3], lo[3], hi[3];
    grid.position(p, centre);
    for (int a = 0; a < 3; ++a) {
      const float c = centre[a] + (moved ? offsets[static_cast<size_t>(p) * 3 + a] : 0.0f);
      lo[a] = c - cell[a];
      hi[a] = c + cell[a];
    }
    for (const View* v : usable)
      if (boxIntersectsFrustum(v->viewProj, lo, hi)) {
        weights[p] = 1.0f;
        break;
      }
  }
  return weights;
}

}  // namespace probecast::session
