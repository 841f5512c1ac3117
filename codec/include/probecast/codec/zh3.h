// ZH3: L1 plus one zonal L2 coefficient per channel around a luminance axis (docs/CODEC.md §2).
// "ZH3: Zonal Harmonics for Real-Time Global Illumination" (Roughton, Activision 2024).
//
// All functions use the probe layout of sh.h (27 floats, coefficient-major, no CS phase).
#pragma once

#include "probecast/codec/sh.h"

namespace probecast {

// Rec. 709 luminance weights used for the shared axis.
constexpr float kLumaWeights[3] = {0.2126f, 0.7152f, 0.0722f};
// Below this length the luminance L1 direction is degenerate and the axis is +z.
constexpr float kZh3AxisEpsilon = 1e-12f;

// Shared zonal axis a = normalize(Σ_k w_k (c3, c1, c2)_k); +z if degenerate. Deterministic:
// encoder and decoder call this same function on the same decoded L1 and get the same bits.
void zh3Axis(const float probe[kProbeFloats], float axis[3]);

// Stored ZH3 coefficient per channel: z_k = (4π/5) (y2(a) · L2_k).
void zh3Project(const float probe[kProbeFloats], const float axis[3], float zonal[3]);

// Expands L1 + zonal coefficients to SH3: L2_m = z · Y2m(a). Writes coefficients 4..8.
void zh3ExpandToL2(float probe[kProbeFloats], const float axis[3], const float zonal[3]);

// Hallucinated zonal coefficients from L1 alone: r = |d_k·a| / c00_k,
// c20' = c00_k (0.08 r + 0.6 r²), z = c20' √(4π/5). Channels with c00 <= 0 get 0.
void zh3Hallucinate(const float probe[kProbeFloats], const float axis[3], float zonal[3]);

// The hallucination curve c20'/c00 as a function of r (docs/CODEC.md §8.4).
float zh3HallucinationCurve(float r);

// Convenience: replaces the L2 band of `probe` by its hallucinated ZH3 expansion.
void zh3HallucinateInPlace(float probe[kProbeFloats]);

}  // namespace probecast
