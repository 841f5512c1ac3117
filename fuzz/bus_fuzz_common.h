// Shared by the bus fuzz target and its seed writer.
#pragma once

#include <cstdint>
#include <vector>

namespace probecast::fuzz {

// Input byte 0 of bus_fuzz: bit 0 set = recompute the message checksum first (so the parser
// behind it sees mutated fields); the rest is the message.
constexpr uint8_t kBusRepairFlag = 1;

// Valid bus messages on the small fuzz layout, every representation: a volume message, a first
// brick version (keyframe only) and a later one (keyframe and delta).
std::vector<std::vector<uint8_t>> sampleBusMessages();
// Recomputes the bus checksum of a message whose header is at least present.
void repairBusChecksum(std::vector<uint8_t>& message);

}  // namespace probecast::fuzz
