#include "probecast/codec/sh.h"

#include <initializer_list>

namespace probecast {

void shEvalBasis(float x, float y, float z, float out[kShCoeffs]) {
  out[0] = kY00;
  out[1] = kY1 * y;
  out[2] = kY1 * z;
  out[3] = kY1 * x;
  out[4] = kY2 * x * y;
  out[5] = kY2 * y * z;
  out[6] = kY20 * (3.0f * z * z - 1.0f);
  out[7] = kY2 * x * z;
  out[8] = kY22 * (x * x - y * y);
}

void shAddSample(float probe[kProbeFloats], float x, float y, float z, const float rgb[3], float weight) {
  float basis[kShCoeffs];
  shEvalBasis(x, y, z, basis);
  for (int i = 0; i < kShCoeffs; ++i) {
    const float b = basis[i] * weight;
    for (int c = 0; c < 3; ++c) probe[i * 3 + c] += b * rgb[c];
  }
}

void shEvalRadiance(const float probe[kProbeFloats], float x, float y, float z, float rgb[3]) {
  float basis[kShCoeffs];
  shEvalBasis(x, y, z, basis);
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  for (int i = 0; i < kShCoeffs; ++i)
    for (int c = 0; c < 3; ++c) rgb[c] += probe[i * 3 + c] * basis[i];
}

void shEvalIrradiance(const float probe[kProbeFloats], float nx, float ny, float nz, float rgb[3], int bands) {
  float basis[kShCoeffs];
  shEvalBasis(nx, ny, nz, basis);
  const int count = bands >= 3 ? kShCoeffs : (bands == 2 ? kShCoeffsL1 : 1);
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  for (int i = 0; i < count; ++i) {
    const float b = basis[i] * kCosineBand[shBand(i)];
    for (int c = 0; c < 3; ++c) rgb[c] += probe[i * 3 + c] * b;
  }
}

void shConvolveCosine(float probe[kProbeFloats]) {
  for (int i = 0; i < kShCoeffs; ++i)
    for (int c = 0; c < 3; ++c) probe[i * 3 + c] *= kCosineBand[shBand(i)];
}

void shToggleCondonShortley(float probe[kProbeFloats]) {
  for (int i : {1, 3, 5, 7})
    for (int c = 0; c < 3; ++c) probe[i * 3 + c] = -probe[i * 3 + c];
}

float shBandEnergy(const float probe[kProbeFloats], int band) {
  const int first = band * band;
  const int last = (band + 1) * (band + 1);
  float sum = 0.0f;
  for (int i = first; i < last; ++i)
    for (int c = 0; c < 3; ++c) sum += probe[i * 3 + c] * probe[i * 3 + c];
  return sum;
}

}  // namespace probecast
