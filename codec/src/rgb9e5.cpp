#include "probecast/codec/rgb9e5.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace probecast {
namespace {

constexpr int kMantissaBits = 9;
constexpr int kExponentBias = 15;
constexpr int kMaxExponent = 31;

float clampChannel(float v) {
  if (std::isnan(v) || v <= 0.0f) return 0.0f;
  return std::min(v, kRgb9e5Max);
}

}  // namespace

uint32_t rgb9e5Encode(const float rgb[3]) {
  const float r = clampChannel(rgb[0]);
  const float g = clampChannel(rgb[1]);
  const float b = clampChannel(rgb[2]);
  const float maxc = std::max(r, std::max(g, b));
  if (maxc == 0.0f) return 0;
  // Shared exponent from the largest channel (EXT_texture_shared_exponent, round to nearest).
  int exp = std::max(-kExponentBias - 1, static_cast<int>(std::floor(std::log2(maxc)))) + 1 + kExponentBias;
  float scale = std::ldexp(1.0f, kExponentBias + kMantissaBits - exp);
  if (static_cast<int>(std::floor(maxc * scale + 0.5f)) == (1 << kMantissaBits)) {
    ++exp;
    scale *= 0.5f;
  }
  exp = std::min(exp, kMaxExponent);
  const auto mant = [&](float v) {
    return static_cast<uint32_t>(std::min(511.0f, std::floor(v * scale + 0.5f)));
  };
  return mant(r) | (mant(g) << 9) | (mant(b) << 18) | (static_cast<uint32_t>(exp) << 27);
}

void rgb9e5Decode(uint32_t packed, float rgb[3]) {
  const int exp = static_cast<int>(packed >> 27);
  const float scale = std::ldexp(1.0f, exp - kExponentBias - kMantissaBits);
  rgb[0] = static_cast<float>(packed & 0x1ffu) * scale;
  rgb[1] = static_cast<float>((packed >> 9) & 0x1ffu) * scale;
  rgb[2] = static_cast<float>((packed >> 18) & 0x1ffu) * scale;
}

uint16_t dcCodeFromValue(float value) {
  if (!(value > 0.0f)) return 0;
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return static_cast<uint16_t>(std::min<uint32_t>(bits >> 15, 0xffffu));
}

float dcValueFromCode(uint16_t code) {
  const uint32_t bits = static_cast<uint32_t>(code) << 15;
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace probecast
