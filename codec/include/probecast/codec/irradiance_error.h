// Irradiance error of SH probes, as `probecast bench codec` reports it (docs/CODEC.md): relative RMSE,
// RGB pooled, no clamping. Irradiance is E(n) = Σ_l Â_l Σ_m c_lm Y_lm(n) (shEvalIrradiance).
#pragma once

#include <cstddef>

#include "probecast/codec/sh.h"

namespace probecast {

// sqrt(Σ |E_probe(n) − E_ref(n)|²) / sqrt(Σ |E_ref(n)|²) over `count` unit normals (3 floats
// each) against reference irradiance (3 floats per normal); 0 when the reference is all zero.
double irradianceRmseRel(const float probe[kProbeFloats], const float* normals, const float* reference, size_t count);

// Exact irradiance error over the whole sphere between two SH3 probes (orthonormality):
// ∫ |ΔE|² dω = Σ_l Â_l² Σ_m Δc_lm². Adds to `err` and to the reference's energy `energy`; the
// relative RMSE of a set of probes is sqrt(err / energy) after adding them all.
void irradianceErrorEnergy(const float test[kProbeFloats], const float ref[kProbeFloats], double& err, double& energy);

}  // namespace probecast
