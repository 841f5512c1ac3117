// Ratio quantisation of SH probes against the decoded DC (docs/CODEC.md §3-4), closed loop.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>

#include "probe_symbols.h"
#include "probecast/codec/half_float.h"
#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/record.h"
#include "probecast/codec/rgb9e5.h"
#include "probecast/codec/zh3.h"

namespace probecast {
namespace {

const float kSqrtFourPiOverFive = std::sqrt(4.0f * kPi / 5.0f);
constexpr int kZh3ZonalFirst = 9;  // narrow index of the first zonal byte in zh3

enum class Range { Snorm, Unorm };
struct Bound {
  Range range;
  float lo;
  float hi;
};

// Bound of the coefficient stored in narrow slot j (coefficient i = 1 + j / 3).
Bound coefficientBound(int j) {
  const int i = 1 + j / 3;
  if (i <= 3) return {Range::Snorm, -kBoundL1, kBoundL1};
  if (i == 6) return {Range::Unorm, kBoundL2ZeroLo, kBoundL2ZeroHi};
  return {Range::Snorm, -kBoundL2Off, kBoundL2Off};
}

// ZH3 zonal bound given r = c10'/c00 on the axis: [√5 (r² − 1)/2, √5].
Bound zonalBound(float r) {
  const float r2 = std::min(r * r, 3.0f);
  return {Range::Unorm, 0.5f * kBoundL2ZeroHi * (r2 - 1.0f), kBoundL2ZeroHi};
}

int quantize(const Bound& b, float ratio) {
  if (std::isnan(ratio)) ratio = 0.0f;
  if (b.range == Range::Snorm) {
    const float t = std::clamp(ratio / b.hi, -1.0f, 1.0f);
    return static_cast<int>(std::lround(t * 127.0f));
  }
  const float span = b.hi - b.lo;
  if (!(span > 1e-6f)) return 0;
  const float t = std::clamp((ratio - b.lo) / span, 0.0f, 1.0f);
  return static_cast<int>(std::lround(t * 255.0f));
}

float dequantize(const Bound& b, int q) {
  if (b.range == Range::Snorm) return static_cast<float>(std::max(q, -127)) / 127.0f * b.hi;
  const float span = b.hi - b.lo;
  if (!(span > 1e-6f)) return b.hi;
  return b.lo + static_cast<float>(q) / 255.0f * span;
}

uint8_t toByte(const Bound& b, int q) {
  return b.range == Range::Snorm ? static_cast<uint8_t>(static_cast<int8_t>(q)) : static_cast<uint8_t>(q);
}
int fromByte(const Bound& b, uint8_t v) {
  return b.range == Range::Snorm ? static_cast<int>(static_cast<int8_t>(v)) : static_cast<int>(v);
}

// Keeps the previous symbol when the new one is within the dead-zone.
int applyDeadzone(int fresh, const ProbeSymbols* previous, const Bound& b, int j, int deadzone) {
  if (!previous) return fresh;
  const int old = fromByte(b, previous->narrow[j]);
  return std::abs(fresh - old) <= deadzone ? old : fresh;
}

// Decoded DC of each channel and the L1 band from symbols (shared by encoder and decoder).
void decodeL1(const ProbeSymbols& s, float probe[kProbeFloats]) {
  for (int c = 0; c < 3; ++c) probe[c] = dcValueFromCode(s.wide[c]);
  for (int j = 0; j < 9; ++j) {
    const int c = j % 3;
    const Bound b = coefficientBound(j);
    probe[3 + j] = probe[c] > 0.0f ? dequantize(b, fromByte(b, s.narrow[j])) * probe[c] : 0.0f;
  }
}

float zonalRatioR(const float probe[kProbeFloats], const float axis[3], int c) {
  const float dc = probe[c];
  const float dot = probe[3 * 3 + c] * axis[0] + probe[1 * 3 + c] * axis[1] + probe[2 * 3 + c] * axis[2];
  return dc > 0.0f ? dot / dc : 0.0f;
}

// zh3h: whether the decoder keeps plain L1 (odd) or hallucinates the L2 band (even), told by the
// parity of the nine L1 ratio symbols' sum (as sign data hiding in HEVC hides a sign in the parity
// of a block's levels): no byte is spent on it.
bool zh3hKeepsL1(const ProbeSymbols& s) {
  unsigned sum = 0;
  for (int j = 0; j < 9; ++j) sum += s.narrow[j];  // two's complement bytes: same parity as the signed sum
  return (sum & 1u) != 0;
}

// The probe a zh3h decoder reconstructs from symbols (decodeL1 done): L1 + hallucinated L2 band,
// or plain L1 when the symbols say so. perPixel: the L2 band is what the renderer adds to its own
// per-pixel hallucination (0, or minus this probe's hallucination to cancel it).
void finishZh3h(const ProbeSymbols& s, float probe[kProbeFloats], bool perPixel) {
  const bool keepL1 = zh3hKeepsL1(s);
  if (!perPixel) {
    if (!keepL1) zh3HallucinateInPlace(probe);
    return;
  }
  if (!keepL1) return;
  zh3HallucinateInPlace(probe);
  for (int k = 4 * 3; k < kProbeFloats; ++k) probe[k] = -probe[k];
}

// Squared irradiance error of `decoded` against `reference` over the sphere, RGB pooled.
double irradianceError2(const float decoded[kProbeFloats], const float reference[kProbeFloats]) {
  double err = 0.0, energy = 0.0;
  irradianceErrorEnergy(decoded, reference, err, energy);
  return err;
}

// zh3h per probe: the symbols as quantised (candidate A) tell one choice by their parity; the
// other choice needs one L1 symbol moved by a step (candidate B), the one whose move adds the least
// squared error. The candidate with the smaller irradiance error against the input's L2 wins; with
// `previous` (a stream), B must be better by a tenth, so that noise does not flip probes (and cost
// a delta) every frame. Rounds symbols toward the ratio the encoder saw: `ratio127[j]` is each
// ratio in symbol steps (ratio / bound × 127, unclamped).
void chooseZh3h(const float probe[kProbeFloats], const float ratio127[9], const float dc[3], bool stream,
                ProbeSymbols* out) {
  float decoded[kProbeFloats];
  const auto errorOf = [&](const ProbeSymbols& s) {
    std::fill(decoded, decoded + kProbeFloats, 0.0f);
    decodeL1(s, decoded);
    finishZh3h(s, decoded, /*perPixel=*/false);
    return irradianceError2(decoded, probe);
  };
  int best = -1, bestTo = 0;
  float bestCost = 0.0f;
  for (int j = 0; j < 9; ++j) {
    const int q = static_cast<int8_t>(out->narrow[j]);
    const float x = std::clamp(ratio127[j], -127.0f, 127.0f);
    int to = x > static_cast<float>(q) ? q + 1 : q - 1;
    if (to > 127 || to < -127) to = 2 * q - to;  // at the end of the range: the other way
    const float scale = dc[j % 3] * kBoundL1 / 127.0f;  // one step of this coefficient, in radiance
    const float moved = static_cast<float>(to) - x, now = static_cast<float>(q) - x;
    const float cost = scale * scale * (moved * moved - now * now);
    if (best < 0 || cost < bestCost) best = j, bestTo = to, bestCost = cost;
  }
  ProbeSymbols other = *out;
  other.narrow[best] = static_cast<uint8_t>(static_cast<int8_t>(bestTo));
  const double a = errorOf(*out), b = errorOf(other);
  if (stream ? b < 0.9 * a : b < a) *out = other;
}

void quantizeFp16(const float probe[kProbeFloats], const ProbeSymbols* previous, int deadzone, ProbeSymbols* out) {
  for (int i = 0; i < kProbeFloats; ++i) {
    const uint16_t half = floatToHalf(probe[i]);
    const int mag = half & 0x7fff;
    int s = (half & 0x8000) ? -mag : mag;
    if (previous) {
      const int old = static_cast<int16_t>(previous->wide[i]);
      if (std::abs(s - old) <= deadzone) s = old;
    }
    out->wide[i] = static_cast<uint16_t>(s);
  }
}

}  // namespace

void sanitizeProbe(float probe[kProbeFloats]) {
  for (int i = 0; i < kProbeFloats; ++i) {
    float& v = probe[i];
    if (std::isnan(v)) v = 0.0f;
    else if (std::isinf(v)) v = v > 0 ? FLT_MAX : -FLT_MAX;
  }
}

bool narrowIsSigned(Representation repr, int j) {
  if (repr == Representation::Zh3 && j >= kZh3ZonalFirst) return false;
  return coefficientBound(j).range == Range::Snorm;
}

void quantizeProbe(Representation repr, const float input[kProbeFloats], const ProbeSymbols* previous, int deadzone,
                   ProbeSymbols* out) {
  float probe[kProbeFloats];
  std::copy(input, input + kProbeFloats, probe);
  sanitizeProbe(probe);
  *out = ProbeSymbols{};
  if (repr == Representation::Fp16) {
    for (float& v : probe) v = std::clamp(v, -65504.0f, 65504.0f);
    quantizeFp16(probe, previous, deadzone, out);
    return;
  }

  // DC: RGB9E5, kept as a whole triple when every channel is within the dead-zone.
  float rgb[3];
  rgb9e5Decode(rgb9e5Encode(probe), rgb);
  uint16_t codes[3];
  int maxMove = 0;
  for (int c = 0; c < 3; ++c) {
    codes[c] = dcCodeFromValue(rgb[c]);
    if (previous) maxMove = std::max(maxMove, std::abs(static_cast<int>(codes[c]) - previous->wide[c]));
  }
  const bool keepDc = previous && maxMove <= deadzone;
  for (int c = 0; c < 3; ++c) out->wide[c] = keepDc ? previous->wide[c] : codes[c];
  float dc[3];
  for (int c = 0; c < 3; ++c) dc[c] = dcValueFromCode(out->wide[c]);

  // Ratios against the decoded DC.
  const int coefficientBytes = repr == Representation::L2 ? 24 : 9;
  float ratio127[9];
  for (int j = 0; j < coefficientBytes; ++j) {
    const int c = j % 3;
    const Bound b = coefficientBound(j);
    const float ratio = dc[c] > 0.0f ? probe[3 + j] / dc[c] : 0.0f;
    if (j < 9) ratio127[j] = std::isfinite(ratio) ? std::clamp(ratio / b.hi * 127.0f, -1e6f, 1e6f) : 0.0f;
    out->narrow[j] = toByte(b, applyDeadzone(quantize(b, ratio), previous, b, j, deadzone));
  }
  if (repr == Representation::Zh3Hallucinated) chooseZh3h(probe, ratio127, dc, previous != nullptr, out);

  if (repr == Representation::Zh3) {
    // Zonal coefficient around the axis of the *decoded* L1, bounded by its decoded r.
    float decoded[kProbeFloats] = {};
    decodeL1(*out, decoded);
    float axis[3];
    zh3Axis(decoded, axis);
    float zonal[3];
    zh3Project(probe, axis, zonal);
    for (int c = 0; c < 3; ++c) {
      const Bound b = zonalBound(zonalRatioR(decoded, axis, c));
      const float ratio = dc[c] > 0.0f ? zonal[c] / kSqrtFourPiOverFive / dc[c] : 0.0f;
      const int j = kZh3ZonalFirst + c;
      out->narrow[j] = toByte(b, applyDeadzone(quantize(b, ratio), previous, b, j, deadzone));
    }
  }
}

bool dequantizeProbe(Representation repr, const ProbeSymbols& s, float probe[kProbeFloats], bool zh3PerPixel,
                     bool zh3hPerProbeChoice) {
  std::fill(probe, probe + kProbeFloats, 0.0f);
  if (repr == Representation::Fp16) {
    for (int i = 0; i < kProbeFloats; ++i) {
      const int v = static_cast<int16_t>(s.wide[i]);
      const int mag = std::abs(v);
      if (mag >= 0x7c00) return false;  // Inf, NaN or the unused -32768
      const uint16_t half = static_cast<uint16_t>((v < 0 ? 0x8000 : 0) | mag);
      probe[i] = halfToFloat(half);
    }
    return true;
  }
  for (int c = 0; c < 3; ++c)
    if (s.wide[c] > kMaxDcCode) return false;
  decodeL1(s, probe);
  switch (repr) {
    case Representation::L1: break;
    case Representation::Zh3Hallucinated:
      if (zh3hPerProbeChoice) finishZh3h(s, probe, zh3PerPixel);
      else if (!zh3PerPixel) zh3HallucinateInPlace(probe);  // codec format 1: every probe hallucinates
      break;
    case Representation::Zh3: {
      float axis[3];
      zh3Axis(probe, axis);
      float zonal[3];
      for (int c = 0; c < 3; ++c) {
        const Bound b = zonalBound(zonalRatioR(probe, axis, c));
        const float ratio = dequantize(b, fromByte(b, s.narrow[kZh3ZonalFirst + c]));
        zonal[c] = probe[c] > 0.0f ? ratio * probe[c] * kSqrtFourPiOverFive : 0.0f;
      }
      zh3ExpandToL2(probe, axis, zonal);
      break;
    }
    case Representation::L2:
      for (int j = 9; j < 24; ++j) {
        const int c = j % 3;
        const Bound b = coefficientBound(j);
        probe[3 + j] = probe[c] > 0.0f ? dequantize(b, fromByte(b, s.narrow[j])) * probe[c] : 0.0f;
      }
      break;
    case Representation::Fp16: break;
  }
  return true;
}

void encodeProbeRecord(Representation repr, const float probe[kProbeFloats], uint8_t* out) {
  ProbeSymbols symbols;
  quantizeProbe(repr, probe, nullptr, 0, &symbols);
  symbolsToRecord(repr, symbols, out);
}

bool decodeProbeRecord(Representation repr, const uint8_t* in, float probe[kProbeFloats], bool zh3PerPixel) {
  ProbeSymbols symbols;
  recordToSymbols(repr, in, &symbols);
  return dequantizeProbe(repr, symbols, probe, zh3PerPixel);
}

}  // namespace probecast
