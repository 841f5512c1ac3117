// libFuzzer target: arbitrary bytes as a binary glTF (.glb), as a viewer receives a scene package
// from a server, loaded and posed. The first 8 bytes choose the scene time. An accepted scene must
// index only its own vertices and materials, keep its counts and triangles at every time it is
// posed, and hold finite bounds.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "probecast/scene/animation.h"
#include "probecast/scene/scene.h"

using namespace probecast::scene;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 8) return 0;
  double time;
  std::memcpy(&time, data, 8);
  static const std::string path = "/tmp/probecast-gltf-fuzz-" + std::to_string(getpid()) + ".glb";
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data + 8), static_cast<std::streamsize>(size - 8));
  Scene s;
  std::string error;
  if (!loadGltf(path, s, error, std::isfinite(time) ? time : 0.0)) {
    require(!error.empty());
    return 0;
  }
  const auto check = [&](const Scene& x) {
    require(x.indices.size() == 3 * x.triangleMaterial.size());
    for (uint32_t i : x.indices) require(i < x.positions.size());
    for (uint32_t m : x.triangleMaterial) require(m < x.materials.size());
    require(x.normals.size() == x.positions.size());
    for (const glm::vec3& p : x.positions) require(std::isfinite(p.x + p.y + p.z));
    require(std::isfinite(x.boundsMin.x + x.boundsMin.y + x.boundsMin.z + x.boundsMax.x + x.boundsMax.y + x.boundsMax.z));
  };
  check(s);
  const std::vector<uint32_t> indices = s.indices;
  const size_t vertices = s.positions.size(), lights = s.lights.size();
  for (double t : {0.0, 0.37, 1.0, 1e9, -5.0}) {
    poseScene(s, t);
    check(s);
    require(s.indices == indices && s.positions.size() == vertices && s.lights.size() == lights);
  }
  return 0;
}
