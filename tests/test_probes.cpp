#include "test_probes.h"

#include <cmath>

namespace probecast::test {

Probe deltaProbe(float x, float y, float z, const float rgb[3]) {
  Probe p{};
  shAddSample(p.data(), x, y, z, rgb, 1.0f);
  return p;
}

void randomDirection(std::mt19937& rng, float d[3]) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  float len2;
  do {
    for (int k = 0; k < 3; ++k) d[k] = u(rng);
    len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  } while (len2 < 1e-4f || len2 > 1.0f);
  const float inv = 1.0f / std::sqrt(len2);
  for (int k = 0; k < 3; ++k) d[k] *= inv;
}

Probe randomNonNegativeProbe(std::mt19937& rng, int lobes, float ambient) {
  std::uniform_real_distribution<float> w(0.0f, 1.0f);
  Probe p{};
  for (int c = 0; c < 3; ++c) p[c] = ambient * 2.0f * std::sqrt(kPi);  // constant radiance = ambient
  for (int i = 0; i < lobes; ++i) {
    float d[3];
    randomDirection(rng, d);
    const float rgb[3] = {w(rng), w(rng), w(rng)};
    shAddSample(p.data(), d[0], d[1], d[2], rgb, 1.0f);
  }
  return p;
}

std::vector<float> movingLightFrame(int count, int frame, float noise, std::mt19937& rng) {
  std::vector<float> out(static_cast<size_t>(count) * kProbeFloats, 0.0f);
  std::normal_distribution<float> n(0.0f, 1.0f);
  const float angle = 0.05f * static_cast<float>(frame);
  const float light[3] = {std::cos(angle) * 2.0f, 1.5f, std::sin(angle) * 2.0f};
  for (int p = 0; p < count; ++p) {
    const float pos[3] = {static_cast<float>(p % 8) * 0.5f - 2.0f, static_cast<float>((p / 8) % 4) * 0.5f,
                          static_cast<float>(p / 32) * 0.5f - 2.0f};
    float d[3] = {light[0] - pos[0], light[1] - pos[1], light[2] - pos[2]};
    const float dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 0.1f;
    const float inv = 1.0f / std::sqrt(dist2);
    for (float& v : d) v *= inv;
    float* probe = out.data() + static_cast<size_t>(p) * kProbeFloats;
    const float ambient[3] = {0.2f, 0.18f, 0.15f};
    for (int c = 0; c < 3; ++c) probe[c] = ambient[c] * 2.0f * std::sqrt(kPi);
    const float rgb[3] = {4.0f / dist2, 3.5f / dist2, 2.5f / dist2};
    // A soft lobe: the delta's bands attenuated (a cosine-power lobe, Funk-Hecke factors ~ 1, 0.75, 0.4).
    float basis[kShCoeffs];
    shEvalBasis(d[0], d[1], d[2], basis);
    const float band[3] = {1.0f, 0.75f, 0.4f};
    for (int i = 0; i < kShCoeffs; ++i)
      for (int c = 0; c < 3; ++c) probe[i * 3 + c] += rgb[c] * basis[i] * band[shBand(i)];
    for (int i = 0; i < kProbeFloats; ++i) probe[i] *= 1.0f + noise * n(rng);
  }
  return out;
}

}  // namespace probecast::test
