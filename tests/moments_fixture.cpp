// The native client's probe-visibility moments (renderer/src/probe_visibility.h) of depth cubes
// whose distances are known functions of direction, as JSON on stdout: the browser page's own
// implementation (web/src/probe_visibility.js) is checked against them (web.probe_visibility).
#include <cstdio>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "probe_visibility.h"

using probecast::renderer::cubeTexelDirection;
using probecast::renderer::kVisibilityCubeSize;

namespace {

// One probe's tile (RS_VIS_TILE² texels × 2 floats) for distance(direction).
std::vector<float> tileOf(const std::function<float(const glm::vec3&)>& distance) {
  const uint32_t n = kVisibilityCubeSize;
  std::vector<float> cube(6 * n * n);
  for (uint32_t f = 0; f < 6; ++f)
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) cube[(f * n + y) * n + x] = distance(cubeTexelDirection(f, x, y, n));
  std::vector<float> tile(RS_VIS_TILE * RS_VIS_TILE * 2);
  probecast::renderer::octahedralMoments(cube.data(), n, tile.data());
  return tile;
}

void print(const char* name, const std::vector<float>& tile, bool last) {
  std::printf("\"%s\": [", name);
  for (size_t i = 0; i < tile.size(); ++i) std::printf("%s%.9g", i ? "," : "", static_cast<double>(tile[i]));
  std::printf("]%s\n", last ? "" : ",");
}

}  // namespace

int main() {
  std::printf("{\"tile\": %d,\n", RS_VIS_TILE);
  // A wall 1 m along +x, open (10 m) elsewhere; and a smooth, lopsided surround.
  print("wall", tileOf([](const glm::vec3& d) { return d.x > 1e-6f ? glm::min(10.0f, 1.0f / d.x) : 10.0f; }), false);
  print("smooth", tileOf([](const glm::vec3& d) { return 1.0f + 0.5f * d.x + 0.25f * d.y * d.y + 0.1f * d.z; }), true);
  std::printf("}\n");
  return 0;
}
