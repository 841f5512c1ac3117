// Probe relocation offsets (ProbeVolume::offsets) and their quantised form on the wire.
//
// An offset moves a probe from its grid position by at most half a cell per axis (the cell of an
// axis is the spacing of its probes, probeCellSize). Descriptions sent to viewers carry each
// component as one signed byte q, the offset q/256 of the cell on that axis, |q| <= 127 (so under
// half a cell), x, y, z per probe in grid order: 3 bytes per probe. Producer and viewers derive
// the same float from the same byte (dequantizeProbeOffsets), and a producer that traces at the
// dequantised positions (snapProbeOffsets) agrees with every viewer bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "probecast/codec/probe_volume.h"

namespace probecast {

constexpr int kOffsetStepsPerCell = 256;  // one step = 1/256 of a cell
constexpr int kMaxOffsetSteps = 127;      // |q| <= 127 steps, under half a cell
constexpr size_t kOffsetBytesPerProbe = 3;

// Spacing of the probes along `axis` (0..2), metres; 0 for an axis of one probe (nothing to move along).
float probeCellSize(const ProbeGrid& grid, int axis);

// Empty, or 3 finite floats per probe, each |offset| <= half the cell on its axis (exactly 0 on an
// axis of one probe). False with the reason in `error`.
bool checkProbeOffsets(const ProbeGrid& grid, const std::vector<float>& offsets, std::string& error);

// Each component rounded to the nearest step and clamped to ±kMaxOffsetSteps (empty in, empty
// out). The offsets must pass checkProbeOffsets (asserted by the caller).
std::vector<int8_t> quantizeProbeOffsets(const ProbeGrid& grid, const std::vector<float>& offsets);

// Offsets from bytes off the wire or a file: `count` must be 0 or 3 per probe, each in
// ±kMaxOffsetSteps and 0 along an axis of one probe. False (out unchanged) with the reason in `why`.
bool dequantizeProbeOffsets(const ProbeGrid& grid, const int8_t* q, size_t count, std::vector<float>& out,
                            std::string& why);

// The offsets moved to the values viewers will reconstruct from their bytes (idempotent).
void snapProbeOffsets(const ProbeGrid& grid, std::vector<float>& offsets);

}  // namespace probecast
