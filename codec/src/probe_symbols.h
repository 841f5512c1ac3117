// Quantised symbols of one probe: what records, keyframes and deltas carry (private to the codec).
//
// Ratio representations: wide[0..2] = monotone DC codes (rgb9e5.h) of R, G, B; narrow[] = the
// ratio bytes in record order. fp16: wide[0..26] = the halves as sign-magnitude mapped to two's
// complement (monotone; +0 is 0), narrow unused. All-zero symbols decode to a black probe, which
// is the state of every inactive probe.
#pragma once

#include <cstdint>

#include "probecast/codec/record.h"

namespace probecast {

constexpr int kMaxWideSymbols = 27;
constexpr int kMaxNarrowSymbols = 24;

struct SymbolShape {
  int wide;
  int narrow;
};

struct ProbeSymbols {
  uint16_t wide[kMaxWideSymbols] = {};
  uint8_t narrow[kMaxNarrowSymbols] = {};
};

SymbolShape symbolShape(Representation repr);
// Whether narrow symbol j is an snorm8 (compared as signed for the dead-zone).
bool narrowIsSigned(Representation repr, int j);

// Quantises a probe. With `previous`, a DC triple whose codes all moved by at most `deadzone`
// keeps the previous codes, and each ratio symbol within `deadzone` steps keeps its previous
// value; ratios are always quantised against the DC the decoder will hold (closed loop).
// zh3h: also chooses per probe between hallucinated ZH3 and plain L1, whichever is nearer the
// input's L2 in irradiance, and tells the choice by the parity of the L1 symbols (record.h),
// moving one symbol by a step where needed.
void quantizeProbe(Representation repr, const float probe[kProbeFloats], const ProbeSymbols* previous, int deadzone,
                   ProbeSymbols* out);

// Reconstructs the probe. Returns false if a symbol is outside its domain. zh3hPerProbeChoice:
// zh3h symbols carry the per-probe choice (codec format 2 on, the default); false reads them as
// format 1 did (every probe hallucinates).
bool dequantizeProbe(Representation repr, const ProbeSymbols& symbols, float probe[kProbeFloats], bool zh3PerPixel,
                     bool zh3hPerProbeChoice = true);

void symbolsToRecord(Representation repr, const ProbeSymbols& symbols, uint8_t* record);
void recordToSymbols(Representation repr, const uint8_t* record, ProbeSymbols* symbols);

}  // namespace probecast
