#include "cpu_path_tracer.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "probecast/codec/sh.h"

namespace probecast::test {
namespace {

using glm::dvec3;

struct Hit {
  double t = -1;
  uint32_t tri = 0;
  bool back = false;
};

// Möller–Trumbore against every triangle.
Hit intersect(const scene::Scene& s, const dvec3& o, const dvec3& d, double tmax) {
  Hit best;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const dvec3 p0 = s.positions[s.indices[3 * t]], p1 = s.positions[s.indices[3 * t + 1]],
                p2 = s.positions[s.indices[3 * t + 2]];
    const dvec3 e1 = p1 - p0, e2 = p2 - p0;
    const dvec3 pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    if (std::fabs(det) < 1e-12) continue;
    const double inv = 1.0 / det;
    const dvec3 tv = o - p0;
    const double u = glm::dot(tv, pv) * inv;
    if (u < 0 || u > 1) continue;
    const dvec3 qv = glm::cross(tv, e1);
    const double v = glm::dot(d, qv) * inv;
    if (v < 0 || u + v > 1) continue;
    const double dist = glm::dot(e2, qv) * inv;
    if (dist > 1e-7 && dist < tmax && (best.t < 0 || dist < best.t)) {
      best.t = dist;
      best.tri = t;
      best.back = det < 0;  // counter-clockwise triangles face the ray when det > 0
    }
  }
  return best;
}

dvec3 brdf(const scene::Material& m, const dvec3& n, const dvec3& wo, const dvec3& wi) {
  const double nl = glm::dot(n, wi), nv = glm::dot(n, wo);
  if (nl <= 0 || nv <= 0) return dvec3(0);
  const dvec3 h = glm::normalize(wo + wi);
  const double nh = std::max(glm::dot(n, h), 0.0), vh = std::max(glm::dot(wo, h), 0.0);
  const double alpha = std::max(double(m.roughness) * m.roughness, 1e-3), a2 = alpha * alpha;
  const double D = a2 / (M_PI * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double k = alpha / 2;
  const double G = nl / (nl * (1 - k) + k) * nv / (nv * (1 - k) + k);
  const dvec3 base(m.baseColor);
  const dvec3 f0 = glm::mix(dvec3(0.04), base, double(m.metallic));
  const dvec3 F = f0 + (1.0 - f0) * std::pow(1 - vh, 5);
  return base * (1.0 - m.metallic) / M_PI + D * G * F / std::max(4 * nl * nv, 1e-6);
}

dvec3 directLight(const scene::Scene& s, const scene::Material& m, const dvec3& p, const dvec3& n, const dvec3& wo) {
  dvec3 sum(0);
  for (const scene::Light& l : s.lights) {
    dvec3 wi;
    double dist;
    dvec3 e = dvec3(l.color) * double(l.intensity);
    if (l.type == scene::LightType::Directional) {
      wi = -glm::normalize(dvec3(l.direction));
      dist = 1e30;
    } else {
      const dvec3 to = dvec3(l.position) - p;
      dist = glm::length(to);
      wi = to / dist;
      e /= dist * dist;
      if (l.range > 0) e *= std::pow(std::clamp(1 - std::pow(dist / l.range, 4.0), 0.0, 1.0), 2.0);
      if (l.type == scene::LightType::Spot) {
        const double c = glm::dot(-wi, glm::normalize(dvec3(l.direction)));
        const double lo = std::cos(l.outerConeAngle), hi = std::cos(l.innerConeAngle);
        const double t = std::clamp((c - lo) / (hi - lo), 0.0, 1.0);
        e *= t * t * (3 - 2 * t);
      }
    }
    const double cosine = glm::dot(n, wi);
    if (cosine <= 0) continue;
    const dvec3 origin = p + n * 1e-5;
    if (intersect(s, origin, wi, dist * (1 - 1e-5)).t >= 0) continue;
    sum += brdf(m, n, wo, wi) * cosine * e;
  }
  return sum;
}

}  // namespace

std::array<double, 27> cpuTraceProbe(const scene::Scene& s, const glm::vec3& position, const CpuTraceOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::array<double, 27> sh{};
  for (uint32_t k = 0; k < o.samples; ++k) {
    const double z = 1 - 2 * U(rng), phi = 2 * M_PI * U(rng), r = std::sqrt(std::max(0.0, 1 - z * z));
    const dvec3 dir0(r * std::cos(phi), r * std::sin(phi), z);
    dvec3 origin(position), dir = dir0, radiance(0), throughput(1);
    for (uint32_t bounce = 0; bounce < o.maxBounces; ++bounce) {
      const Hit h = intersect(s, origin, dir, 1e30);
      if (h.t < 0) break;
      const scene::Material& m = s.materials[s.triangleMaterial[h.tri]];
      const dvec3 p0 = s.positions[s.indices[3 * h.tri]], p1 = s.positions[s.indices[3 * h.tri + 1]],
                  p2 = s.positions[s.indices[3 * h.tri + 2]];
      dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      if (glm::dot(n, dir) > 0) n = -n;
      const dvec3 p = origin + dir * h.t;
      if (!h.back) radiance += throughput * dvec3(m.emission);
      const dvec3 wo = -dir;
      radiance += throughput * directLight(s, m, p, n, wo);
      if (bounce + 1 >= o.maxBounces) break;
      // Continue with a cosine-weighted direction (a different sampler than the GPU's mixture).
      const double u1 = U(rng), u2 = U(rng);
      const dvec3 t = glm::normalize(std::fabs(n.x) > 0.5 ? glm::cross(n, dvec3(0, 1, 0)) : glm::cross(n, dvec3(1, 0, 0)));
      const dvec3 b = glm::cross(n, t);
      const double rr = std::sqrt(u1), ph = 2 * M_PI * u2;
      const dvec3 wi = glm::normalize(t * (rr * std::cos(ph)) + b * (rr * std::sin(ph)) + n * std::sqrt(1 - u1));
      const double pdf = glm::dot(n, wi) / M_PI;
      if (pdf <= 1e-12) break;
      throughput *= brdf(m, n, wo, wi) * glm::dot(n, wi) / pdf;
      if (bounce >= 2) {
        const double q = std::clamp(std::max({throughput.x, throughput.y, throughput.z}), 0.05, 0.95);
        if (U(rng) > q) break;
        throughput /= q;
      }
      origin = p + n * 1e-5;
      dir = wi;
    }
    float y[kShCoeffs];
    shEvalBasis(float(dir0.x), float(dir0.y), float(dir0.z), y);
    for (int i = 0; i < kShCoeffs; ++i)
      for (int c = 0; c < 3; ++c) sh[i * 3 + c] += radiance[c] * y[i];
  }
  for (double& v : sh) v *= 4 * M_PI / o.samples;
  return sh;
}

}  // namespace probecast::test
