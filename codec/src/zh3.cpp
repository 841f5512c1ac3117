#include "probecast/codec/zh3.h"

#include <cmath>

namespace probecast {
namespace {

constexpr float kFourPiOverFive = 4.0f * kPi / 5.0f;
const float kSqrtFourPiOverFive = std::sqrt(4.0f * kPi / 5.0f);

// y2(a): the five band-2 basis values at the axis.
void band2AtAxis(const float axis[3], float y2[5]) {
  float basis[kShCoeffs];
  shEvalBasis(axis[0], axis[1], axis[2], basis);
  for (int m = 0; m < 5; ++m) y2[m] = basis[4 + m];
}

// L1 direction (c3, c1, c2) of channel c.
void l1Direction(const float probe[kProbeFloats], int c, float d[3]) {
  d[0] = probe[3 * 3 + c];
  d[1] = probe[1 * 3 + c];
  d[2] = probe[2 * 3 + c];
}

}  // namespace

void zh3Axis(const float probe[kProbeFloats], float axis[3]) {
  float a[3] = {0.0f, 0.0f, 0.0f};
  for (int c = 0; c < 3; ++c) {
    float d[3];
    l1Direction(probe, c, d);
    for (int k = 0; k < 3; ++k) a[k] += kLumaWeights[c] * d[k];
  }
  const float len2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  if (!(len2 > kZh3AxisEpsilon * kZh3AxisEpsilon) || !std::isfinite(len2)) {
    axis[0] = 0.0f;
    axis[1] = 0.0f;
    axis[2] = 1.0f;
    return;
  }
  const float inv = 1.0f / std::sqrt(len2);
  for (int k = 0; k < 3; ++k) axis[k] = a[k] * inv;
}

void zh3Project(const float probe[kProbeFloats], const float axis[3], float zonal[3]) {
  float y2[5];
  band2AtAxis(axis, y2);
  for (int c = 0; c < 3; ++c) {
    float dot = 0.0f;
    for (int m = 0; m < 5; ++m) dot += y2[m] * probe[(4 + m) * 3 + c];
    zonal[c] = kFourPiOverFive * dot;
  }
}

void zh3ExpandToL2(float probe[kProbeFloats], const float axis[3], const float zonal[3]) {
  float y2[5];
  band2AtAxis(axis, y2);
  for (int m = 0; m < 5; ++m)
    for (int c = 0; c < 3; ++c) probe[(4 + m) * 3 + c] = zonal[c] * y2[m];
}

float zh3HallucinationCurve(float r) { return 0.08f * r + 0.6f * r * r; }

void zh3Hallucinate(const float probe[kProbeFloats], const float axis[3], float zonal[3]) {
  for (int c = 0; c < 3; ++c) {
    const float c00 = probe[c];
    if (!(c00 > 0.0f)) {
      zonal[c] = 0.0f;
      continue;
    }
    float d[3];
    l1Direction(probe, c, d);
    const float r = std::fabs(d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]) / c00;
    zonal[c] = c00 * zh3HallucinationCurve(r) * kSqrtFourPiOverFive;
  }
}

void zh3HallucinateInPlace(float probe[kProbeFloats]) {
  float axis[3];
  float zonal[3];
  zh3Axis(probe, axis);
  zh3Hallucinate(probe, axis, zonal);
  zh3ExpandToL2(probe, axis, zonal);
}

}  // namespace probecast
