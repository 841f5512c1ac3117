// The probe volume (probe_volume.h).
#include "probecast/codec/probe_volume.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "probecast/codec/internal/crc32c.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/stream.h"

namespace probecast {

void ProbeGrid::position(uint32_t index, float out[3]) const {
  const uint32_t c[3] = {index % dims[0], (index / dims[0]) % dims[1], index / (dims[0] * dims[1])};
  for (int a = 0; a < 3; ++a) {
    const float t = dims[a] > 1 ? static_cast<float>(c[a]) / static_cast<float>(dims[a] - 1) : 0.5f;
    out[a] = bounds.min[a] + (bounds.max[a] - bounds.min[a]) * t;
  }
}

ProbeGrid cellCentredGrid(const uint32_t dims[3], const float lo[3], const float hi[3]) {
  ProbeGrid g;
  for (int a = 0; a < 3; ++a) {
    g.dims[a] = dims[a];
    const float cell = (hi[a] - lo[a]) / static_cast<float>(dims[a]);
    g.bounds.min[a] = lo[a] + 0.5f * cell;
    g.bounds.max[a] = hi[a] - 0.5f * cell;
  }
  return g;
}

ProbeVolume makeProbeVolume(const ProbeGrid& grid) {
  ProbeVolume v;
  v.grid = grid;
  v.probes.assign(static_cast<size_t>(grid.count()) * kProbeFloats, 0.0f);
  v.active.assign(grid.count(), 1);
  return v;
}

bool checkProbeVolume(const ProbeVolume& v, std::string& error) {
  uint64_t count = 1;
  for (int a = 0; a < 3; ++a) {
    if (v.grid.dims[a] < 1 || v.grid.dims[a] > static_cast<uint32_t>(kMaxGridDim))
      return error = "probe volume: " + std::to_string(v.grid.dims[a]) + " probes along an axis (1 to " +
                     std::to_string(kMaxGridDim) + ")",
             false;
    count *= v.grid.dims[a];
  }
  if (count > kMaxProbes) return error = "probe volume: " + std::to_string(count) + " probes is too many", false;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(v.grid.bounds.min[a]) || !std::isfinite(v.grid.bounds.max[a]) ||
        (v.grid.dims[a] > 1 && !(v.grid.bounds.max[a] > v.grid.bounds.min[a])))
      return error = "probe volume bounds must be finite with max > min along every axis of 2+ probes", false;
  if (v.probes.size() != count * kProbeFloats)
    return error = "probe volume: " + std::to_string(v.probes.size()) + " floats for " + std::to_string(count) +
                   " probes (27 each)",
           false;
  if (v.active.size() != count)
    return error = "probe volume: active mask of " + std::to_string(v.active.size()) + " entries for " +
                   std::to_string(count) + " probes",
           false;
  if (std::any_of(v.active.begin(), v.active.end(), [](uint8_t a) { return a > 1; }))
    return error = "probe volume: active mask holds a value other than 0 or 1", false;
  for (size_t i = 0; i < v.probes.size(); ++i)
    if (!std::isfinite(v.probes[i]))
      return error = "probe volume: non-finite coefficient at probe " + std::to_string(i / kProbeFloats), false;
  if (!v.noise.empty() && v.noise.size() != count)
    return error = "probe volume: noise of " + std::to_string(v.noise.size()) + " entries for " + std::to_string(count) +
                   " probes (one each, or none)",
           false;
  for (size_t i = 0; i < v.noise.size(); ++i)
    if (!(std::isfinite(v.noise[i]) && v.noise[i] >= 0.0f))
      return error = "probe volume: noise of probe " + std::to_string(i) + " is not a finite value >= 0", false;
  if (!v.stillUpdates.empty() && v.stillUpdates.size() != count)
    return error = "probe volume: stillUpdates of " + std::to_string(v.stillUpdates.size()) + " entries for " +
                   std::to_string(count) + " probes (one each, or none)",
           false;
  return checkAreaLightRule(v.areaLights, error) && checkProbeOffsets(v.grid, v.offsets, error);
}

bool checkAreaLightRule(const AreaLightRule& r, std::string& error) {
  if (r.version == 0) {
    if (r.minPowerFraction != 0.0f) return error = "client area lights are off but a threshold is given", false;
    return true;
  }
  if (r.version != kAreaLightRuleVersion)
    return error = "client area light rule version " + std::to_string(r.version) + " is unknown (this build knows " +
                   std::to_string(kAreaLightRuleVersion) + ")",
           false;
  if (!(r.minPowerFraction >= 0.0f && r.minPowerFraction <= 1.0f))  // NaN fails too
    return error = "client area light threshold is not a power share in [0, 1]", false;
  return true;
}

ProbeVolume decodeAs(const ProbeVolume& volume, Representation repr, bool zh3PerPixel) {
  ProbeVolume out = volume;
  out.decodedFrom = repr;
  out.zh3PerPixel = zh3PerPixel && repr == Representation::Zh3Hallucinated;
  uint8_t record[kMaxRecordBytes];
  for (size_t p = 0; p * kProbeFloats < out.probes.size(); ++p) {
    float* probe = out.probes.data() + p * kProbeFloats;
    encodeProbeRecord(repr, probe, record);
    if (!decodeProbeRecord(repr, record, probe, out.zh3PerPixel)) std::fill(probe, probe + kProbeFloats, 0.0f);
  }
  return out;
}

uint32_t volumeChecksum(const ProbeVolume& volume) {
  static_assert(std::endian::native == std::endian::little, "the checksum reads floats as little-endian bytes");
  uint32_t crc = crc32c(reinterpret_cast<const uint8_t*>(volume.probes.data()), volume.probes.size() * sizeof(float));
  crc = crc32c(volume.active.data(), volume.active.size(), crc);
  return crc32c(reinterpret_cast<const uint8_t*>(volume.offsets.data()), volume.offsets.size() * sizeof(float), crc);
}

}  // namespace probecast
