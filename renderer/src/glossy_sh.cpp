#include "probecast/renderer/glossy_sh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace probecast::renderer {
namespace {

double ggxD(double cosH, double alpha) {
  const double a2 = alpha * alpha;
  const double d = cosH * cosH * (a2 - 1.0) + 1.0;
  return a2 / (M_PI * d * d);
}

double legendre(int l, double t) {
  switch (l) {
    case 0: return 1.0;
    case 1: return t;
    default: return 0.5 * (3.0 * t * t - 1.0);
  }
}

// Solves the n×n system m x = v by Gaussian elimination with partial pivoting.
template <int N>
std::array<double, N> solve(double m[N][N], double v[N]) {
  for (int c = 0; c < N; ++c) {
    int pivot = c;
    for (int r = c + 1; r < N; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c])) pivot = r;
    std::swap(m[c], m[pivot]);
    std::swap(v[c], v[pivot]);
    for (int r = c + 1; r < N; ++r) {
      const double f = m[r][c] / m[c][c];
      for (int k = c; k < N; ++k) m[r][k] -= f * m[c][k];
      v[r] -= f * v[c];
    }
  }
  std::array<double, N> x{};
  for (int r = N - 1; r >= 0; --r) {
    double sum = v[r];
    for (int k = r + 1; k < N; ++k) sum -= m[r][k] * x[k];
    x[r] = sum / m[r][r];
  }
  return x;
}

}  // namespace

std::array<double, 3> ggxLobeScalesIntegrated(double roughness) {
  const double alpha = std::max(roughness * roughness, 1e-4);
  // Midpoint rule in θ over the hemisphere, fine enough for the sharpest lobe we fit (r ≥ 0.05).
  const int n = 20000;
  double moments[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const double theta = (i + 0.5) / n * (M_PI / 2);
    const double t = std::cos(theta);
    const double k = ggxD(std::cos(theta / 2), alpha) * t * std::sin(theta);  // dω = 2π sin θ dθ
    for (int l = 0; l < 3; ++l) moments[l] += k * legendre(l, t);
  }
  return {1.0, moments[1] / moments[0], moments[2] / moments[0]};
}

std::array<double, 3> GgxLobeFit::evaluate(double r) const {
  const double a = r * r;
  auto g = [a](const std::array<double, 4>& c) { return (1 + c[0] * a + c[1] * a * a) / (1 + c[2] * a + c[3] * a * a); };
  return {1.0, g(band1), g(band2)};
}

GgxLobeFit ggxLobeFit() {
  GgxLobeFit fit{};
  // g (1 + q1 α + q2 α²) = 1 + p1 α + p2 α²  ⇔  p1 α + p2 α² − q1 α g − q2 α² g = g − 1 (linear).
  for (int l = 1; l <= 2; ++l) {
    double m[4][4] = {}, v[4] = {};
    for (int i = 1; i <= 40; ++i) {
      const double r = i / 40.0, a = r * r;
      const double g = ggxLobeScalesIntegrated(r)[l];
      const double basis[4] = {a, a * a, -a * g, -a * a * g};
      for (int j = 0; j < 4; ++j) {
        v[j] += basis[j] * (g - 1);
        for (int k = 0; k < 4; ++k) m[j][k] += basis[j] * basis[k];
      }
    }
    (l == 1 ? fit.band1 : fit.band2) = solve<4>(m, v);
  }
  return fit;
}

std::vector<float> envBrdfTable(int size, int samples) {
  std::vector<float> table(static_cast<size_t>(size) * size * 2);
  for (int ri = 0; ri < size; ++ri) {
    const double roughness = (ri + 0.5) / size;
    const double alpha = roughness * roughness, k = alpha / 2;
    for (int vi = 0; vi < size; ++vi) {
      const double nv = (vi + 0.5) / size;
      const double v[3] = {std::sqrt(1 - nv * nv), 0.0, nv};
      double a = 0, b = 0;
      for (int s = 0; s < samples; ++s) {
        // Hammersley point → GGX half vector.
        uint32_t bits = static_cast<uint32_t>(s);
        bits = (bits << 16u) | (bits >> 16u);
        bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
        bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
        bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
        bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
        const double u1 = (s + 0.5) / samples, u2 = bits * (1.0 / 4294967296.0);
        const double phi = 2 * M_PI * u1;
        const double cosT = std::sqrt((1 - u2) / (1 + (alpha * alpha - 1) * u2));
        const double sinT = std::sqrt(1 - cosT * cosT);
        const double h[3] = {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
        const double vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        const double l[3] = {2 * vh * h[0] - v[0], 2 * vh * h[1] - v[1], 2 * vh * h[2] - v[2]};
        const double nl = l[2], nh = h[2];
        if (nl <= 0 || vh <= 0) continue;
        const double g = nl / (nl * (1 - k) + k) * nv / (nv * (1 - k) + k);
        // f cos / pdf with pdf = D nh / (4 vh): G vh / (nh nv), split by Schlick's Fresnel.
        const double gv = g * vh / (nh * nv);
        const double fc = std::pow(1 - vh, 5);
        a += (1 - fc) * gv;
        b += fc * gv;
      }
      table[(static_cast<size_t>(ri) * size + vi) * 2] = static_cast<float>(a / samples);
      table[(static_cast<size_t>(ri) * size + vi) * 2 + 1] = static_cast<float>(b / samples);
    }
  }
  return table;
}

}  // namespace probecast::renderer
