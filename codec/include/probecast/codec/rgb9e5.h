// Shared-exponent RGB9E5 (EXT_texture_shared_exponent): 9-bit mantissas, 5-bit exponent, bias 15.
// R bits 0-8, G 9-17, B 18-26, E 27-31. Largest value 65408. Each channel decodes to
// m · 2^(E-24); the largest channel keeps 9 significant bits (relative error <= 2^-10 after
// rounding), smaller channels share its exponent.
#pragma once

#include <cstdint>

namespace probecast {

constexpr float kRgb9e5Max = 65408.0f;  // 511/512 · 2^16

// Non-finite and negative inputs: NaN and negatives -> 0, +Inf -> kRgb9e5Max.
uint32_t rgb9e5Encode(const float rgb[3]);
void rgb9e5Decode(uint32_t packed, float rgb[3]);

// Monotone 16-bit code of a decoded channel value: the IEEE float bits >> 15 (sign, exponent and
// 8 fraction bits; every RGB9E5 channel value is exact in it). 0 encodes 0. Deltas of DC values
// are taken in this domain.
uint16_t dcCodeFromValue(float value);
float dcValueFromCode(uint16_t code);
// Largest code an RGB9E5 channel can produce (65408).
constexpr uint16_t kMaxDcCode = 36607;

}  // namespace probecast
