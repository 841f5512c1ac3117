// Probe volume files: a baked grid of float L2 SH probes plus the active mask, for inspection,
// the codec benchmark and serving without tracing.
//
// Little-endian: magic "PCPV" | u32 version (4) | u32 nx, ny, nz | f32 min[3], max[3] (metres,
// positions of the first and last probe) | u32 updates | u32 samplesPerProbe | f32 probes[n × 27]
// (sh.h layout: coefficient-major RGB, no Condon-Shortley phase, radiance) | u8 active[n] |
// u32 m | f32 offsets[m] (m = 0 or 3n, ProbeVolume::offsets in metres) | u32 area light rule version
// | f32 its threshold (ProbeVolume::areaLights) | u8 scene hash[32] | f64 scene time | u32 s |
// scene manifest[s] (ProbeVolume::scene; s = 0: unknown, hash all zero) | u32 CRC-32C of everything
// before it. Version 3 files (no scene: unknown), version 2 files (no rule) and version 1 files (no
// m, no offsets either) are still read, their rule as none: they were made before any emitter was
// left out of the probes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "probecast/codec/probe_volume.h"

namespace probecast {

void serializeProbeVolume(const ProbeVolume& volume, std::vector<uint8_t>& out);
// Checks magic, version, sizes, checksum, that every value is finite, the offsets within half a
// cell (checkProbeOffsets) and the area light rule valid (checkAreaLightRule); `error` says what failed.
bool parseProbeVolume(const uint8_t* data, size_t size, ProbeVolume& volume, std::string& error);

// Refuses a zh3PerPixel volume (L1 only): a file's samples are read back as full L2.
bool writeProbeFile(const std::string& path, const ProbeVolume& volume, std::string& error);
bool readProbeFile(const std::string& path, ProbeVolume& volume, std::string& error);

}  // namespace probecast
