// Geometry helpers and spatial ordering of triangles.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/scene/animation.h"
#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

// Spreads the low 10 bits of v so there are two zero bits between each.
uint32_t spreadBits(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

}  // namespace

uint32_t triangleClass(const Scene& s, uint32_t t) {
  const uint32_t m = s.triangleMaterial[t];
  if (m >= s.materials.size()) return 0;
  const Material& mat = s.materials[m];
  return mat.transmissive() ? 2u : (mat.opaqueToRays() ? 0u : 1u);
}

std::vector<uint8_t> movingVertices(const Scene& s) {
  std::vector<uint8_t> out(s.positions.size(), 0);
  if (!s.rig || !(s.rig->duration > 0.0f)) return out;  // posed once at load: nothing moves later
  for (const RigPrimitive& p : s.rig->primitives)
    for (uint32_t v = p.firstVertex; v < p.firstVertex + p.vertexCount && v < out.size(); ++v) out[v] = 1;
  return out;
}

std::vector<uint8_t> movingTriangles(const Scene& s) {
  const std::vector<uint8_t> vertex = movingVertices(s);
  std::vector<uint8_t> out(s.triangleCount(), 0);
  for (uint32_t t = 0; t < s.triangleCount(); ++t)
    out[t] = vertex[s.indices[3 * t]] | vertex[s.indices[3 * t + 1]] | vertex[s.indices[3 * t + 2]];
  return out;
}

uint32_t leadingTrianglesBelowClass(const Scene& s, uint32_t cls) {
  uint32_t n = 0;
  while (n < s.triangleCount() && triangleClass(s, n) < cls) ++n;
  return n;
}

void addQuad(Scene& s, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
             uint32_t material) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  const uint32_t base = static_cast<uint32_t>(s.positions.size());
  const glm::vec2 uv[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  int k = 0;
  for (const glm::vec3& p : {a, b, c, d}) {
    s.positions.push_back(p);
    s.normals.push_back(n);
    s.texcoords.push_back(uv[k++]);
  }
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + i);
  s.triangleMaterial.push_back(material);
  s.triangleMaterial.push_back(material);
}

void addBox(Scene& s, const glm::vec3& center, const glm::vec3& h, float angle, uint32_t material) {
  const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1.0f), center), angle, glm::vec3(0, 1, 0));
  auto P = [&](float x, float y, float z) { return glm::vec3(m * glm::vec4(x * h.x, y * h.y, z * h.z, 1.0f)); };
  addQuad(s, P(-1, 1, 1), P(1, 1, 1), P(1, 1, -1), P(-1, 1, -1), material);      // top +Y
  addQuad(s, P(-1, -1, -1), P(1, -1, -1), P(1, -1, 1), P(-1, -1, 1), material);  // bottom −Y
  addQuad(s, P(-1, -1, 1), P(1, -1, 1), P(1, 1, 1), P(-1, 1, 1), material);      // front +Z
  addQuad(s, P(1, -1, -1), P(-1, -1, -1), P(-1, 1, -1), P(1, 1, -1), material);  // back −Z
  addQuad(s, P(1, -1, 1), P(1, -1, -1), P(1, 1, -1), P(1, 1, 1), material);      // right +X
  addQuad(s, P(-1, -1, -1), P(-1, -1, 1), P(-1, 1, 1), P(-1, 1, -1), material);  // left −X
}

void finalizeScene(Scene& s) {
  s.boundsMin = glm::vec3(INFINITY);
  s.boundsMax = glm::vec3(-INFINITY);
  for (const glm::vec3& p : s.positions) {
    s.boundsMin = glm::min(s.boundsMin, p);
    s.boundsMax = glm::max(s.boundsMax, p);
  }
  const uint32_t count = s.triangleCount();
  if (count == 0) return;
  const glm::vec3 extent = glm::max(s.boundsMax - s.boundsMin, glm::vec3(1e-6f));
  const std::vector<uint8_t> moves = movingTriangles(s);
  std::vector<uint64_t> code(count);
  for (uint32_t t = 0; t < count; ++t) {
    const glm::vec3 c =
        (s.positions[s.indices[3 * t]] + s.positions[s.indices[3 * t + 1]] + s.positions[s.indices[3 * t + 2]]) / 3.0f;
    glm::vec3 u = glm::clamp((c - s.boundsMin) / extent, 0.0f, 1.0f) * 1023.0f;
    for (int a = 0; a < 3; ++a)
      if (!(u[a] >= 0.0f && u[a] <= 1023.0f)) u[a] = 0.0f;  // non-finite corners (the loader then refuses the scene)
    // The class in bits 32-33 keeps each class one run; within it the triangles that never move
    // come first, those that move after (bit 31), each in Morton order.
    code[t] = (uint64_t{triangleClass(s, t)} << 32) | (uint64_t{moves[t]} << 31) | spreadBits(static_cast<uint32_t>(u.x)) |
              (spreadBits(static_cast<uint32_t>(u.y)) << 1) | (spreadBits(static_cast<uint32_t>(u.z)) << 2);
  }
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
  std::vector<uint32_t> indices(s.indices.size()), materials(count);
  for (uint32_t k = 0; k < count; ++k) {
    for (int j = 0; j < 3; ++j) indices[3 * k + j] = s.indices[3 * order[k] + j];
    materials[k] = s.triangleMaterial[order[k]];
  }
  s.indices = std::move(indices);
  s.triangleMaterial = std::move(materials);
}

}  // namespace probecast::scene
