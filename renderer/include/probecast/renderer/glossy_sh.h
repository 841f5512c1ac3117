// Glossy indirect light from SH probes by the split sum (as DDISH-GI does):
//   specular ≈ prefiltered(R) · (F0 · A + B),
//   prefiltered(R) = Σ_l g_l(roughness) Σ_m c_lm Y_lm(R),
// with g_l the zonal-harmonic scales of the GGX lobe and (A, B) the environment BRDF.
//
// The lobe is the distribution of reflected directions around R for n = v = R (Karis' split-sum
// assumption), weighted by cos θ: K(θ) ∝ D_GGX(θ/2) · cos θ on the hemisphere around R, with
// α = roughness². By Funk–Hecke a normalised zonal kernel scales band l by
// g_l = 2π ∫ K(t) P_l(t) dt (t = cos θ), so g_0 = 1.
#pragma once

#include <array>
#include <vector>

namespace probecast::renderer {

// g_l(roughness) by numerical integration (the ground truth of the fit).
std::array<double, 3> ggxLobeScalesIntegrated(double roughness);

// The fitted curves used at render time, rational in α = roughness²:
//   g_l = (1 + p1 α + p2 α²) / (1 + q1 α + q2 α²),  l = 1, 2 (g_0 = 1),
// from a linearised least-squares fit over roughness in (0, 1] (ggxLobeFit()).
struct GgxLobeFit {
  std::array<double, 4> band1;  // p1, p2, q1, q2 of l = 1
  std::array<double, 4> band2;  // p1, p2, q1, q2 of l = 2
  std::array<double, 3> evaluate(double roughness) const;
};
GgxLobeFit ggxLobeFit();

// Environment BRDF (A, B) such that ∫ f_spec cos = F0·A + B, by importance-sampling GGX with
// Smith-Schlick G (k = α/2) and Schlick Fresnel, over (n·v, roughness) on a size × size grid
// (texel centres). Row-major: [roughness][n·v], 2 floats each.
std::vector<float> envBrdfTable(int size, int samples);

}  // namespace probecast::renderer
