#include "probecast/codec/equirect.h"

#include <algorithm>
#include <cmath>

namespace probecast {

void equirectDirection(int width, int height, int x, int y, float dir[3]) {
  const float theta = kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
  const float phi = 2.0f * kPi * ((static_cast<float>(x) + 0.5f) / static_cast<float>(width) - 0.5f);
  dir[0] = std::sin(theta) * std::sin(phi);
  dir[1] = std::cos(theta);
  dir[2] = -std::sin(theta) * std::cos(phi);
}

void equirectPixel(int width, int height, const float dir[3], int& x, int& y) {
  const float theta = std::acos(std::clamp(dir[1], -1.0f, 1.0f));
  const float phi = std::atan2(dir[0], -dir[2]);
  const float u = phi / (2.0f * kPi) + 0.5f, v = theta / kPi;
  if (!std::isfinite(u) || !std::isfinite(v)) {  // not a direction: the first pixel, never out of range
    x = y = 0;
    return;
  }
  x = std::clamp(static_cast<int>(u * static_cast<float>(width)), 0, width - 1);
  y = std::clamp(static_cast<int>(v * static_cast<float>(height)), 0, height - 1);
}

float equirectPixelSolidAngle(int width, int height, int y) {
  const float t0 = kPi * static_cast<float>(y) / static_cast<float>(height);
  const float t1 = kPi * static_cast<float>(y + 1) / static_cast<float>(height);
  return 2.0f * kPi / static_cast<float>(width) * (std::cos(t0) - std::cos(t1));
}

std::vector<float> equirectDownsample(const float* rgb, int width, int height, int factor, int& outWidth,
                                      int& outHeight) {
  outWidth = std::max(1, width / factor);
  outHeight = std::max(1, height / factor);
  std::vector<float> out(static_cast<size_t>(outWidth) * outHeight * 3, 0.0f);
  std::vector<double> weight(static_cast<size_t>(outWidth) * outHeight, 0.0);
  std::vector<double> acc(out.size(), 0.0);
  for (int y = 0; y < height; ++y) {
    const double w = equirectPixelSolidAngle(width, height, y);
    const int oy = std::min(outHeight - 1, y / factor);
    for (int x = 0; x < width; ++x) {
      const int ox = std::min(outWidth - 1, x / factor);
      const size_t o = static_cast<size_t>(oy) * outWidth + ox;
      const size_t i = (static_cast<size_t>(y) * width + x) * 3;
      weight[o] += w;
      for (int c = 0; c < 3; ++c) acc[o * 3 + c] += w * rgb[i + c];
    }
  }
  for (size_t o = 0; o < weight.size(); ++o)
    for (int c = 0; c < 3; ++c) out[o * 3 + c] = weight[o] > 0 ? static_cast<float>(acc[o * 3 + c] / weight[o]) : 0.0f;
  return out;
}

void equirectProjectSh(const float* rgb, int width, int height, float probe[kProbeFloats], float rotationY) {
  double acc[kProbeFloats] = {};
  const float cr = std::cos(rotationY), sr = std::sin(rotationY);
  for (int y = 0; y < height; ++y) {
    const double dw = equirectPixelSolidAngle(width, height, y);
    for (int x = 0; x < width; ++x) {
      float d[3];
      equirectDirection(width, height, x, y, d);
      const float rx = cr * d[0] + sr * d[2];
      const float rz = -sr * d[0] + cr * d[2];
      float basis[kShCoeffs];
      shEvalBasis(rx, d[1], rz, basis);
      const float* L = &rgb[(static_cast<size_t>(y) * width + x) * 3];
      for (int i = 0; i < kShCoeffs; ++i)
        for (int c = 0; c < 3; ++c) acc[i * 3 + c] += dw * basis[i] * L[c];
    }
  }
  for (int i = 0; i < kProbeFloats; ++i) probe[i] = static_cast<float>(acc[i]);
}

void equirectIrradiance(const float* rgb, int width, int height, const float* normals, size_t count,
                        float* irradiance) {
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<float> dirs(pixels * 3), weighted(pixels * 3);
  for (int y = 0; y < height; ++y) {
    const float dw = equirectPixelSolidAngle(width, height, y);
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      equirectDirection(width, height, x, y, &dirs[i * 3]);
      for (int c = 0; c < 3; ++c) weighted[i * 3 + c] = rgb[i * 3 + c] * dw;
    }
  }
  for (size_t n = 0; n < count; ++n) {
    const float* nn = &normals[n * 3];
    double e[3] = {0, 0, 0};
    for (size_t i = 0; i < pixels; ++i) {
      const float cosine = nn[0] * dirs[i * 3] + nn[1] * dirs[i * 3 + 1] + nn[2] * dirs[i * 3 + 2];
      if (cosine <= 0.0f) continue;
      for (int c = 0; c < 3; ++c) e[c] += cosine * weighted[i * 3 + c];
    }
    for (int c = 0; c < 3; ++c) irradiance[n * 3 + c] = static_cast<float>(e[c]);
  }
}

std::vector<float> fibonacciSphere(int count) {
  std::vector<float> out(static_cast<size_t>(count) * 3);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out[i * 3] = static_cast<float>(r * std::cos(golden * i));
    out[i * 3 + 1] = static_cast<float>(r * std::sin(golden * i));
    out[i * 3 + 2] = static_cast<float>(z);
  }
  return out;
}

}  // namespace probecast
