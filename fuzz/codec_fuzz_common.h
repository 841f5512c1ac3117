// Shared by the fuzz target and its seed writer.
#pragma once

#include <cstdint>
#include <vector>

#include "probecast/codec/stream.h"

namespace probecast::fuzz {

// Input byte 0 selects what the rest of the input is:
//   bits 0-2: representation index (mod 5), bits 3-4: mode
//   mode 0: a frame for a fresh decoder; mode 1: a frame for a decoder holding the base keyframe
//   (checksums repaired first when bit 5 is set, so the payload parsers see the bytes);
//   mode 2: record bytes; mode 3: floats for the encoder (round trip must be bit-exact).
//   bit 6 set: the rest is a probe volume file (probe_file.h) instead.
//   bit 7 set: frames and encoders use a per-brick representation (kErrorBound; a zh3 or l2
//   stream then mixes l1, zh3 and l2 bricks).
enum Mode : uint8_t { kFrameFresh = 0, kFrameOnBase = 1, kRecord = 2, kEncodeFloats = 3 };
constexpr uint8_t kRepairFlag = 1u << 5;
constexpr uint8_t kPerBrickFlag = 1u << 7;
constexpr float kErrorBound = 0.05f;

StreamLayout fuzzLayout(Representation repr);
// The base keyframe (mode 1) and a delta that applies to it; `perBrick`: with kErrorBound.
// `smallDelta` (when given): another delta on the same keyframe that changes one probe a little, so
// the seeds hold each of format 3's delta forms (a changed list, one-byte DC differences).
void baseFrames(Representation repr, std::vector<uint8_t>& keyframe, std::vector<uint8_t>& delta, bool perBrick = false,
                std::vector<uint8_t>* smallDelta = nullptr);
void repairChecksums(std::vector<uint8_t>& frame);

}  // namespace probecast::fuzz
