// Probe volume files: a baked grid of float L2 SH probes plus the active mask, for inspection,
// the codec benchmark and serving without tracing.
//
// Little-endian: magic "PCPV" | u32 version (1) | u32 nx, ny, nz | f32 min[3], max[3] (metres,
// positions of the first and last probe) | u32 updates | u32 samplesPerProbe | f32 probes[n × 27]
// (sh.h layout: coefficient-major RGB, no Condon-Shortley phase, radiance) | u8 active[n] |
// u32 CRC-32C of everything before it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace probecast {

struct ProbeVolume {
  uint32_t dims[3] = {0, 0, 0};
  float boundsMin[3] = {0, 0, 0};
  float boundsMax[3] = {0, 0, 0};
  uint32_t updates = 0;
  uint32_t samplesPerProbe = 0;
  std::vector<float> probes;    // 27 floats per probe
  std::vector<uint8_t> active;  // 1 = active
  uint32_t count() const { return dims[0] * dims[1] * dims[2]; }
};

void serializeProbeVolume(const ProbeVolume& volume, std::vector<uint8_t>& out);
// Checks magic, version, sizes, checksum and that every value is finite; `error` says what failed.
bool parseProbeVolume(const uint8_t* data, size_t size, ProbeVolume& volume, std::string& error);

bool writeProbeFile(const std::string& path, const ProbeVolume& volume, std::string& error);
bool readProbeFile(const std::string& path, ProbeVolume& volume, std::string& error);

}  // namespace probecast
