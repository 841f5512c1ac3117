#include "probe_surfaces.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace probecast::renderer {

bool triangleMeetsBox(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& centre,
                      const glm::vec3& half) {
  const glm::vec3 v[3] = {a - centre, b - centre, c - centre};
  // The projections of the triangle and the box onto `axis` do not overlap.
  const auto apart = [&](const glm::vec3& axis) {
    const float p0 = glm::dot(v[0], axis), p1 = glm::dot(v[1], axis), p2 = glm::dot(v[2], axis);
    const float r = half.x * std::fabs(axis.x) + half.y * std::fabs(axis.y) + half.z * std::fabs(axis.z);
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  for (int k = 0; k < 3; ++k) {
    glm::vec3 axis(0.0f);
    axis[k] = 1.0f;
    if (apart(axis)) return false;
  }
  const glm::vec3 edges[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  if (apart(glm::cross(edges[0], edges[1]))) return false;  // a degenerate triangle's zero normal never separates
  for (const glm::vec3& e : edges)
    for (int k = 0; k < 3; ++k) {
      glm::vec3 unit(0.0f);
      unit[k] = 1.0f;
      if (apart(glm::cross(unit, e))) return false;
    }
  return true;
}

std::vector<uint8_t> probesNearSurfaces(const scene::Scene& scene, const ProbeGrid& grid) {
  std::vector<uint8_t> near(grid.count(), 0);
  float lo[3], spacing[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = grid.bounds.min[a];
    spacing[a] = grid.dims[a] > 1 ? (grid.bounds.max[a] - grid.bounds.min[a]) / static_cast<float>(grid.dims[a] - 1) : 0.0f;
  }
  const uint32_t triangles = scene.triangleCount();
  for (uint32_t t = 0; t < triangles; ++t) {
    const glm::vec3& p0 = scene.positions[scene.indices[3 * t]];
    const glm::vec3& p1 = scene.positions[scene.indices[3 * t + 1]];
    const glm::vec3& p2 = scene.positions[scene.indices[3 * t + 2]];
    const glm::vec3 tmin = glm::min(p0, glm::min(p1, p2)), tmax = glm::max(p0, glm::max(p1, p2));
    const auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    if (!finite(tmin) || !finite(tmax)) continue;  // a corner that is nowhere lights no cell
    // Probes whose box can meet the triangle's bounding box: lo + (i ± 1) s against [tmin, tmax].
    uint32_t first[3], last[3];
    for (int a = 0; a < 3; ++a) {
      const uint32_t n = grid.dims[a];
      if (n <= 1 || !(spacing[a] > 0.0f)) {
        first[a] = 0;
        last[a] = n - 1;
        continue;
      }
      const double from = std::floor((static_cast<double>(tmin[a]) - lo[a]) / spacing[a] - 1.0);
      const double to = std::ceil((static_cast<double>(tmax[a]) - lo[a]) / spacing[a] + 1.0);
      const double top = static_cast<double>(n - 1);  // a triangle beyond the grid lights the face probes
      first[a] = static_cast<uint32_t>(std::clamp(from, 0.0, top));
      last[a] = static_cast<uint32_t>(std::clamp(to, 0.0, top));
    }
    for (uint32_t z = first[2]; z <= last[2]; ++z)
      for (uint32_t y = first[1]; y <= last[1]; ++y)
        for (uint32_t x = first[0]; x <= last[0]; ++x) {
          const uint32_t index = x + grid.dims[0] * (y + grid.dims[1] * z);
          if (near[index]) continue;
          const uint32_t i[3] = {x, y, z};
          glm::vec3 centre, half;
          for (int a = 0; a < 3; ++a) {
            const float reach = spacing[a] * (1.0f - kSurfaceBoxSlack);
            const float at = lo[a] + spacing[a] * static_cast<float>(i[a]);
            // The box along this axis, open to infinity past the grid's last probes: as far as
            // the triangle reaches there.
            float from = i[a] == 0 || !(spacing[a] > 0.0f) ? std::min(tmin[a], at) - 1.0f : at - reach;
            float to = i[a] + 1 == grid.dims[a] || !(spacing[a] > 0.0f) ? std::max(tmax[a], at) + 1.0f : at + reach;
            centre[a] = 0.5f * (from + to);
            half[a] = 0.5f * (to - from);
          }
          if (triangleMeetsBox(p0, p1, p2, centre, half)) near[index] = 1;
        }
  }
  return near;
}

}  // namespace probecast::renderer
