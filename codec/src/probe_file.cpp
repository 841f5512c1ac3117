// Probe volume files (probe_file.h).
#include "probecast/codec/probe_file.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "byte_io.h"
#include "probecast/codec/crc32c.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/stream.h"

namespace probecast {
namespace {

constexpr uint8_t kMagic[4] = {'P', 'C', 'P', 'V'};
constexpr uint32_t kVersion = 4;  // 2 adds the offsets, 3 the area light rule, 4 the scene; 1 to 3 are still read
constexpr size_t kHeaderBytes = 4 + 4 + 12 + 24 + 8;

void putF32(std::vector<uint8_t>& out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  putU32(out, bits);
}
float getF32(const uint8_t* p) {
  const uint32_t bits = getU32(p);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

// Version 4's scene: u8 hash[32] | f64 time (two u32, low first) | u32 m | manifest[m].
bool readScene(const uint8_t* p, uint64_t manifestBytes, SceneStamp& scene, std::string& error) {
  std::memcpy(scene.hash.data(), p, 32);
  const uint64_t timeBits = getU32(p + 32) | (static_cast<uint64_t>(getU32(p + 36)) << 32);
  std::memcpy(&scene.time, &timeBits, 8);
  if (!std::isfinite(scene.time)) return error = "probe file scene time is not finite", false;
  scene.manifest.assign(reinterpret_cast<const char*>(p + 44), manifestBytes);
  if (scene.manifest.empty() && scene.hash != SceneStamp{}.hash)
    return error = "probe file names a scene hash without its manifest", false;
  return true;
}

}  // namespace

void serializeProbeVolume(const ProbeVolume& v, std::vector<uint8_t>& out) {
  out.assign(std::begin(kMagic), std::end(kMagic));
  out.reserve(kHeaderBytes + v.probes.size() * 4 + v.active.size() + 4);
  putU32(out, kVersion);
  for (uint32_t d : v.grid.dims) putU32(out, d);
  for (float f : v.grid.bounds.min) putF32(out, f);
  for (float f : v.grid.bounds.max) putF32(out, f);
  putU32(out, v.updates);
  putU32(out, v.samplesPerProbe);
  for (float f : v.probes) putF32(out, f);
  out.insert(out.end(), v.active.begin(), v.active.end());
  putU32(out, static_cast<uint32_t>(v.offsets.size()));
  for (float f : v.offsets) putF32(out, f);
  putU32(out, v.areaLights.version);
  putF32(out, v.areaLights.minPowerFraction);
  out.insert(out.end(), v.scene.hash.begin(), v.scene.hash.end());
  uint64_t timeBits;
  std::memcpy(&timeBits, &v.scene.time, 8);
  putU32(out, static_cast<uint32_t>(timeBits));
  putU32(out, static_cast<uint32_t>(timeBits >> 32));
  putU32(out, static_cast<uint32_t>(v.scene.manifest.size()));
  out.insert(out.end(), v.scene.manifest.begin(), v.scene.manifest.end());
  putU32(out, crc32c(out.data(), out.size()));
}

bool parseProbeVolume(const uint8_t* data, size_t size, ProbeVolume& v, std::string& error) {
  if (size < kHeaderBytes + 4) return error = "truncated probe file header", false;
  if (std::memcmp(data, kMagic, 4) != 0) return error = "not a probecast probe file (bad magic)", false;
  const uint32_t version = getU32(data + 4);
  if (version < 1 || version > kVersion)
    return error = "unsupported probe file version " + std::to_string(version) + " (this build reads 1 to 4)", false;
  ProbeVolume out;
  uint64_t count = 1;
  for (int a = 0; a < 3; ++a) {
    out.grid.dims[a] = getU32(data + 8 + 4 * a);
    if (out.grid.dims[a] < 1 || out.grid.dims[a] > kMaxGridDim) return error = "probe grid dimension out of range", false;
    count *= out.grid.dims[a];
  }
  if (count > kMaxProbes) return error = "probe grid too large", false;
  for (int a = 0; a < 3; ++a) {
    out.grid.bounds.min[a] = getF32(data + 20 + 4 * a);
    out.grid.bounds.max[a] = getF32(data + 32 + 4 * a);
    if (!std::isfinite(out.grid.bounds.min[a]) || !std::isfinite(out.grid.bounds.max[a])) return error = "non-finite bounds", false;
  }
  out.updates = getU32(data + 44);
  out.samplesPerProbe = getU32(data + 48);
  // Version 2: u32 number of offset floats (0 or 3 per probe), then the floats.
  const uint64_t samplesEnd = kHeaderBytes + count * 27 * 4 + count;
  uint64_t offsetFloats = 0;
  if (version >= 2) {
    if (size < samplesEnd + 4 + 4) return error = "probe file truncated before its offsets", false;
    offsetFloats = getU32(data + samplesEnd);
    if (offsetFloats != 0 && offsetFloats != count * 3)
      return error = "probe file holds " + std::to_string(offsetFloats) + " offset floats for " +
                     std::to_string(count) + " probes (3 each, or none)",
             false;
  }
  const uint64_t ruleAt = samplesEnd + (version >= 2 ? 4 + offsetFloats * 4 : 0);
  const uint64_t sceneAt = ruleAt + (version >= 3 ? 8 : 0);
  uint64_t manifestBytes = 0;
  if (version >= 4) {
    if (size < sceneAt + 44 + 4) return error = "probe file truncated before its scene", false;
    manifestBytes = getU32(data + sceneAt + 40);
    if (manifestBytes > kMaxSceneManifestBytes)
      return error = "probe file scene manifest of " + std::to_string(manifestBytes) + " bytes (at most " +
                     std::to_string(kMaxSceneManifestBytes) + ")", false;
  }
  const uint64_t expected = sceneAt + (version >= 4 ? 44 + manifestBytes : 0) + 4;
  if (size != expected)
    return error = "probe file is " + std::to_string(size) + " bytes, expected " + std::to_string(expected), false;
  if (crc32c(data, size - 4) != getU32(data + size - 4)) return error = "probe file checksum mismatch", false;
  out.probes.resize(count * 27);
  const uint8_t* p = data + kHeaderBytes;
  for (size_t i = 0; i < out.probes.size(); ++i) {
    out.probes[i] = getF32(p + 4 * i);
    if (!std::isfinite(out.probes[i])) return error = "probe " + std::to_string(i / 27) + " holds NaN or Inf", false;
  }
  out.active.assign(p + count * 27 * 4, p + count * 27 * 4 + count);
  for (uint8_t a : out.active)
    if (a > 1) return error = "active mask holds a value other than 0 or 1", false;
  out.offsets.resize(offsetFloats);
  for (size_t i = 0; i < out.offsets.size(); ++i) out.offsets[i] = getF32(data + samplesEnd + 4 + 4 * i);
  if (!checkProbeOffsets(out.grid, out.offsets, error)) return false;
  if (version >= 3) {
    out.areaLights.version = getU32(data + ruleAt);
    out.areaLights.minPowerFraction = getF32(data + ruleAt + 4);
    if (!checkAreaLightRule(out.areaLights, error)) return false;
  }
  if (version >= 4 && !readScene(data + sceneAt, manifestBytes, out.scene, error)) return false;
  v = std::move(out);
  return true;
}

bool writeProbeFile(const std::string& path, const ProbeVolume& volume, std::string& error) {
  if (volume.zh3PerPixel)
    return error = path + ": a zh3h volume decoded L1-only (zh3PerPixel) cannot be stored as L2 samples", false;
  std::vector<uint8_t> bytes;
  serializeProbeVolume(volume, bytes);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) return error = path + ": cannot write", false;
  return true;
}

bool readProbeFile(const std::string& path, ProbeVolume& volume, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return error = path + ": cannot open", false;
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!parseProbeVolume(bytes.data(), bytes.size(), volume, error)) return error = path + ": " + error, false;
  return true;
}

}  // namespace probecast
