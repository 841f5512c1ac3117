// Record bytes <-> symbols, and the representation table.
#include "probe_symbols.h"

#include <cassert>

#include "probecast/codec/half_float.h"
#include "probecast/codec/rgb9e5.h"

namespace probecast {

size_t recordSize(Representation repr) {
  switch (repr) {
    case Representation::L1:
    case Representation::Zh3Hallucinated: return 13;
    case Representation::Zh3: return 16;
    case Representation::L2: return 28;
    case Representation::Fp16: return 56;
  }
  assert(false && "invalid representation");
  return 0;
}

const char* representationName(Representation repr) {
  switch (repr) {
    case Representation::L1: return "l1";
    case Representation::Zh3Hallucinated: return "zh3h";
    case Representation::Zh3: return "zh3";
    case Representation::L2: return "l2";
    case Representation::Fp16: return "fp16";
  }
  return "invalid";
}

std::optional<Representation> parseRepresentation(std::string_view name) {
  for (Representation r : kAllRepresentations)
    if (name == representationName(r)) return r;
  return std::nullopt;
}

bool isValidRepresentation(uint8_t value) { return value >= 1 && value <= 5; }

SymbolShape symbolShape(Representation repr) {
  if (repr == Representation::Fp16) return {kProbeFloats, 0};
  return {3, static_cast<int>(recordSize(repr)) - 4};
}

void symbolsToRecord(Representation repr, const ProbeSymbols& symbols, uint8_t* record) {
  if (repr == Representation::Fp16) {
    for (int i = 0; i < kProbeFloats; ++i) {
      const int16_t s = static_cast<int16_t>(symbols.wide[i]);
      const uint16_t half = s < 0 ? static_cast<uint16_t>(0x8000 | -s) : static_cast<uint16_t>(s);
      record[2 * i] = static_cast<uint8_t>(half & 0xff);
      record[2 * i + 1] = static_cast<uint8_t>(half >> 8);
    }
    record[54] = 0;
    record[55] = 0;
    return;
  }
  const float rgb[3] = {dcValueFromCode(symbols.wide[0]), dcValueFromCode(symbols.wide[1]),
                        dcValueFromCode(symbols.wide[2])};
  const uint32_t packed = rgb9e5Encode(rgb);
  for (int b = 0; b < 4; ++b) record[b] = static_cast<uint8_t>(packed >> (8 * b));
  const int narrow = symbolShape(repr).narrow;
  for (int j = 0; j < narrow; ++j) record[4 + j] = symbols.narrow[j];
}

void recordToSymbols(Representation repr, const uint8_t* record, ProbeSymbols* symbols) {
  *symbols = ProbeSymbols{};
  if (repr == Representation::Fp16) {
    for (int i = 0; i < kProbeFloats; ++i) {
      const uint16_t half = static_cast<uint16_t>(record[2 * i] | (record[2 * i + 1] << 8));
      const int mag = half & 0x7fff;
      symbols->wide[i] = static_cast<uint16_t>((half & 0x8000) ? -mag : mag);
    }
    return;
  }
  uint32_t packed = 0;
  for (int b = 0; b < 4; ++b) packed |= static_cast<uint32_t>(record[b]) << (8 * b);
  float rgb[3];
  rgb9e5Decode(packed, rgb);
  for (int c = 0; c < 3; ++c) symbols->wide[c] = dcCodeFromValue(rgb[c]);
  const int narrow = symbolShape(repr).narrow;
  for (int j = 0; j < narrow; ++j) symbols->narrow[j] = record[4 + j];
}

}  // namespace probecast
