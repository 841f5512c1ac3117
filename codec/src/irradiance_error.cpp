#include "probecast/codec/irradiance_error.h"

#include <cmath>

namespace probecast {

double irradianceRmseRel(const float probe[kProbeFloats], const float* normals, const float* reference, size_t count) {
  double num = 0, den = 0;
  for (size_t n = 0; n < count; ++n) {
    float e[3];
    shEvalIrradiance(probe, normals[n * 3], normals[n * 3 + 1], normals[n * 3 + 2], e);
    for (int c = 0; c < 3; ++c) {
      const double d = e[c] - reference[n * 3 + c];
      num += d * d;
      den += static_cast<double>(reference[n * 3 + c]) * reference[n * 3 + c];
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

void irradianceErrorEnergy(const float test[kProbeFloats], const float ref[kProbeFloats], double& err, double& energy) {
  for (int i = 0; i < kShCoeffs; ++i) {
    const double a2 = static_cast<double>(kCosineBand[shBand(i)]) * kCosineBand[shBand(i)];
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(test[i * 3 + c]) - ref[i * 3 + c];
      err += a2 * d * d;
      energy += a2 * static_cast<double>(ref[i * 3 + c]) * ref[i * 3 + c];
    }
  }
}

}  // namespace probecast
