// Which emitters the client lights itself (area_lights.h).
#include "probecast/scene/area_lights.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace probecast::scene {
namespace {

constexpr float kPi = 3.14159265358979f;

float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

glm::vec3 corner(const Scene& s, uint32_t t, int k) { return s.positions[s.indices[3 * t + k]]; }

float triangleArea(const Scene& s, uint32_t t) {
  return 0.5f * glm::length(glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)));
}

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// Splits `triangles` into pieces that share a vertex position (exactly: glTF meshes repeat
// positions across primitives, so indices alone would split one panel).
std::vector<std::vector<uint32_t>> connectedPieces(const Scene& s, const std::vector<uint32_t>& triangles) {
  std::vector<uint32_t> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  std::map<std::tuple<float, float, float>, uint32_t> owner;
  for (uint32_t i = 0; i < triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p = corner(s, triangles[i], k);
      const auto [it, inserted] = owner.emplace(std::make_tuple(p.x, p.y, p.z), i);
      if (!inserted) parent[findRoot(parent, i)] = findRoot(parent, it->second);
    }
  std::map<uint32_t, std::vector<uint32_t>> byRoot;
  for (uint32_t i = 0; i < triangles.size(); ++i) byRoot[findRoot(parent, i)].push_back(triangles[i]);
  std::vector<std::vector<uint32_t>> pieces;
  for (auto& [root, piece] : byRoot) pieces.push_back(std::move(piece));
  return pieces;
}

AreaLight makeLight(const Scene& s, uint32_t material, const std::vector<uint32_t>& piece) {
  AreaLight l;
  l.material = material;
  l.radiance = s.materials[material].emission;
  glm::vec3 weightedNormal(0.0f), weightedCentroid(0.0f);
  for (uint32_t t : piece) {
    const glm::vec3 a = corner(s, t, 0), b = corner(s, t, 1), c = corner(s, t, 2);
    const glm::vec3 cr = glm::cross(b - a, c - a);
    const float area = 0.5f * glm::length(cr);
    l.corners.insert(l.corners.end(), {a, b, c});
    weightedNormal += 0.5f * cr;
    weightedCentroid += area * (a + b + c) / 3.0f;
    l.area += area;
  }
  l.centroid = l.area > 0.0f ? weightedCentroid / l.area : l.corners[0];
  const float len = glm::length(weightedNormal);
  if (len > 0.0f) l.normal = weightedNormal / len;
  l.power = luminance(l.radiance) * l.area * kPi;
  return l;
}

}  // namespace

AreaLightSet extractAreaLights(const Scene& s, const AreaLightOptions& o) {
  if (!(o.minPowerFraction >= 0.0f && o.minPowerFraction <= 1.0f))  // NaN too
    throw std::invalid_argument("area lights: the minimum power share must be in [0, 1]");
  AreaLightSet out;
  out.clientLitMaterial.assign(s.materials.size(), 0);
  // Power per material, and the triangles of each untextured emissive material.
  std::vector<double> materialPower(s.materials.size(), 0.0);
  std::vector<std::vector<uint32_t>> materialTriangles(s.materials.size());
  double total = 0.0;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const uint32_t m = s.triangleMaterial[t];
    if (m >= s.materials.size()) continue;
    const double power = static_cast<double>(luminance(s.materials[m].emission)) * triangleArea(s, t) * kPi;
    if (!(power > 0.0) || !std::isfinite(power)) continue;
    total += power;
    materialPower[m] += power;
    materialTriangles[m].push_back(t);
  }
  out.totalEmittedPower = static_cast<float>(total);
  if (!o.enabled || !(total > 0.0) || !std::isfinite(total)) return out;
  std::vector<uint32_t> order(s.materials.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return materialPower[a] > materialPower[b]; });
  uint32_t triangles = 0;
  for (uint32_t m : order) {
    const Material& mat = s.materials[m];
    // Textured emission is not constant; a transmissive or cut-out emitter is not a solid panel.
    if (mat.emissiveTexture >= 0 || !mat.opaqueToRays() || materialTriangles[m].empty()) continue;
    if (materialPower[m] < static_cast<double>(o.minPowerFraction) * total) break;  // the rest are weaker
    const auto pieces = connectedPieces(s, materialTriangles[m]);
    // A material is client-lit whole or not at all: the updater's rule is per material.
    if (out.lights.size() + pieces.size() > o.maxLights || triangles + materialTriangles[m].size() > o.maxTriangles)
      continue;
    for (const auto& piece : pieces) out.lights.push_back(makeLight(s, m, piece));
    triangles += static_cast<uint32_t>(materialTriangles[m].size());
    out.clientLitMaterial[m] = 1;
  }
  return out;
}

}  // namespace probecast::scene
