// The renderer's dielectric BRDF (Lambert + GGX, Smith-Schlick G, Schlick F, F0 = 0.04; as
// path_trace.glsl and cpu_path_tracer.cpp) written out in double for known-answer tests, and its
// directional albedo by midpoint quadrature.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace probecast::test {

// f(wo, wi) about unit normal n; base colour rho, metallic 0.
inline double dielectricBrdf(double rho, double roughness, const glm::dvec3& n, const glm::dvec3& wo,
                             const glm::dvec3& wi) {
  const double nl = glm::dot(n, wi), nv = glm::dot(n, wo);
  if (nl <= 0 || nv <= 0) return 0;
  const glm::dvec3 h = glm::normalize(wo + wi);
  const double nh = std::clamp(glm::dot(n, h), 0.0, 1.0), vh = std::clamp(glm::dot(wo, h), 0.0, 1.0);
  const double a = std::max(roughness * roughness, 1e-3), a2 = a * a, k = a / 2;
  const double dd = nh * nh * (a2 - 1) + 1;
  const double d = a2 / (M_PI * dd * dd);
  const double g = nl / (nl * (1 - k) + k) * nv / (nv * (1 - k) + k);
  const double f = 0.04 + 0.96 * std::pow(1 - vh, 5);
  return rho / M_PI + d * g * f / std::max(4 * nl * nv, 1e-6);
}

// A(wo) = ∫ f(wo, wi) cos θi dωi for wo at cos θo = `mu` from the normal, by midpoint quadrature
// in (θi, φi) over the hemisphere (nt × 2nt cells).
inline double directionalAlbedo(double rho, double roughness, double mu, int nt = 400) {
  const glm::dvec3 n(0, 0, 1), wo(std::sqrt(std::max(0.0, 1 - mu * mu)), 0, mu);
  const int np = 2 * nt;
  double sum = 0;
  for (int i = 0; i < nt; ++i) {
    const double theta = (i + 0.5) / nt * M_PI / 2, st = std::sin(theta), ct = std::cos(theta);
    for (int j = 0; j < np; ++j) {
      const double phi = (j + 0.5) / np * 2 * M_PI;
      const glm::dvec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
      sum += dielectricBrdf(rho, roughness, n, wo, wi) * ct * st;
    }
  }
  return sum * (M_PI / 2 / nt) * (2 * M_PI / np);
}

}  // namespace probecast::test
