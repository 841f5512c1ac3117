// Real spherical harmonics, bands 0..2, and the probe layout shared by every module.
//
// Convention (docs/CODEC.md §1): real SH without the Condon-Shortley phase (Ramamoorthi-Hanrahan
// 2001), index i = l(l+1)+m, order [00, 1-1, 10, 11, 2-2, 2-1, 20, 21, 22], direction (x, y, z)
// with z the pole. Probes hold SH of incident *radiance*.
//
// Probe layout: 27 floats, coefficient-major: probe[i * 3 + channel], channel 0/1/2 = R/G/B.
#pragma once

#include <cstddef>
#include <cstdint>

namespace probecast {

constexpr int kShCoeffs = 9;          // L2: bands 0..2
constexpr int kShCoeffsL1 = 4;        // L1: bands 0..1
constexpr int kProbeFloats = kShCoeffs * 3;
static_assert(kProbeFloats == 27, "L2 RGB probe is 27 floats");

constexpr float kPi = 3.14159265358979323846f;

// Basis constants (docs/CODEC.md §1 table; sqrt((2l+1)/(4π) · (l-|m|)!/(l+|m|)!) times the polynomial's factor).
constexpr float kY00 = 0.282094792f;   // 1/(2√π)
constexpr float kY1 = 0.488602512f;    // √3/(2√π)
constexpr float kY2 = 1.092548431f;    // √15/(2√π)
constexpr float kY20 = 0.315391565f;   // √5/(4√π)
constexpr float kY22 = 0.546274215f;   // √15/(4√π)

// Clamped-cosine convolution weights per band: Â_l = (π, 2π/3, π/4) (Ramamoorthi-Hanrahan 2001).
constexpr float kCosineBand[3] = {kPi, 2.0f * kPi / 3.0f, kPi / 4.0f};

// Band of coefficient i.
constexpr int shBand(int i) { return i == 0 ? 0 : (i < 4 ? 1 : 2); }

// Evaluates the 9 basis functions at a unit direction.
void shEvalBasis(float x, float y, float z, float out[kShCoeffs]);

// Adds weight * radiance(rgb) * Y(direction) to an SH3 probe (projection helper for Monte Carlo
// sums: ĉ = (4π/S) Σ L(ω_s) Y(ω_s) is shAddSample with weight 4π/S).
void shAddSample(float probe[kProbeFloats], float x, float y, float z, const float rgb[3], float weight);

// Evaluates the radiance an SH3 probe represents in a direction (no clamping).
void shEvalRadiance(const float probe[kProbeFloats], float x, float y, float z, float rgb[3]);

// Irradiance E(n) = Σ_l Â_l Σ_m c_lm Y_lm(n) for a unit normal n (not divided by π, not clamped).
// `bands` = 2 uses only L0..L1, 3 uses L0..L2.
void shEvalIrradiance(const float probe[kProbeFloats], float nx, float ny, float nz, float rgb[3], int bands = 3);

// Converts radiance SH to irradiance SH in place (multiplies band l by Â_l).
void shConvolveCosine(float probe[kProbeFloats]);

// Condon-Shortley phase conversion: negates coefficients 1, 3, 5, 7 (an involution, so the same
// function converts in both directions).
void shToggleCondonShortley(float probe[kProbeFloats]);

// Sum of squares of band l over the three channels (rotation invariant).
float shBandEnergy(const float probe[kProbeFloats], int band);

}  // namespace probecast
