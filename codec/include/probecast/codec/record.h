// Per-probe records ("ratio encoding", docs/CODEC.md §3-4) and the representations a stream carries.
//
// A record holds the DC (RGB c00) as RGB9E5 in 4 bytes and every other coefficient as one byte:
// its ratio to the *decoded* DC of its channel, divided by the tight bound for non-negative
// functions, quantised (snorm8 for symmetric ranges, unorm8 over [lo, hi] otherwise).
//
//   representation  record bytes  content
//   l1              13            DC + 9 L1 ratios
//   zh3h            13            as l1; per probe the decoder hallucinates the zonal L2
//                                 (zh3.h) or keeps plain L1, as the encoder chose (below)
//   zh3             16            as l1 + 3 zonal ratios around the axis of the decoded L1
//   l2              28            DC + 9 L1 + 15 L2 ratios
//   fp16            56            27 IEEE half floats + 1 zero pad half (DDISH-GI baseline,
//                                 7 RGBA16F texels)
//
// Byte order: DC as little-endian uint32 (R bits 0-8, G 9-17, B 18-26, exponent 27-31), then the
// ratio bytes in coefficient order i = 1..8 (l1/zh3h/zh3: i = 1..3), channels R, G, B within
// each coefficient; zh3 appends the zonal bytes R, G, B.
//
// zh3h per-probe choice (codec format 2): the encoder, which sees the probe's L2, decodes it both
// ways and keeps whichever is nearer in irradiance; an even sum of the nine L1 ratio bytes means
// hallucinate, odd means plain L1. Where its parity tells the other choice, the encoder moves the
// one L1 ratio whose move by a step costs least (at most one step on one coefficient per probe),
// so zh3h stays 13 bytes and is never worse than l1 by more than that step.
//
// Untrusted values (documented behaviour, tested):
// - NaN becomes 0; +Inf becomes the largest finite value of the field; -Inf the smallest.
// - A negative or zero DC makes that channel black: all its coefficients decode to 0.
// - Ratios outside the bounds are clamped to the bounds (path-traced noise can step outside).
// - DC above 65408 (the RGB9E5 maximum) saturates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "probecast/codec/sh.h"

namespace probecast {

enum class Representation : uint8_t {
  L1 = 1,
  Zh3Hallucinated = 2,
  Zh3 = 3,
  L2 = 4,
  Fp16 = 5,
};

constexpr Representation kAllRepresentations[] = {Representation::L1, Representation::Zh3Hallucinated,
                                                  Representation::Zh3, Representation::L2,
                                                  Representation::Fp16};

constexpr size_t kMaxRecordBytes = 56;

// Record size in bytes: 13, 13, 16, 28, 56.
size_t recordSize(Representation repr);
// "l1", "zh3h", "zh3", "l2", "fp16".
const char* representationName(Representation repr);
std::optional<Representation> parseRepresentation(std::string_view name);
bool isValidRepresentation(uint8_t value);

// Ratio bounds for non-negative functions (docs/CODEC.md §3).
constexpr float kBoundL1 = 1.7320508f;         // √3
constexpr float kBoundL2Off = 1.9364917f;      // √15/2, m = ±1, ±2
constexpr float kBoundL2ZeroLo = -1.1180340f;  // -√5/2, m = 0
constexpr float kBoundL2ZeroHi = 2.2360680f;   // √5, m = 0 and ZH3 zonal upper bound

// Encodes one probe (27 floats, sh.h layout) into `out` (recordSize(repr) bytes).
// Closed loop: ratios are taken against the DC the decoder will reconstruct.
void encodeProbeRecord(Representation repr, const float probe[kProbeFloats], uint8_t* out);

// Decodes one record into 27 floats. For zh3h, `zh3PerPixel` chooses between the probe as chosen
// (false: hallucinated L2 band or plain L1) and the form of a renderer that interpolates first and
// hallucinates per pixel (true: L1 and a band that is 0, or cancels the hallucination;
// ProbeVolume::zh3PerPixel).
// Returns false only for fp16 records holding Inf or NaN (ratio records always decode).
bool decodeProbeRecord(Representation repr, const uint8_t* in, float probe[kProbeFloats], bool zh3PerPixel = false);

// Replaces non-finite values as documented above (NaN -> 0, ±Inf -> ±FLT_MAX).
void sanitizeProbe(float probe[kProbeFloats]);

}  // namespace probecast
