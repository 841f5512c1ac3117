#include "probecast/service/bus_format.h"

#include <bit>
#include <cmath>
#include <cstring>

#include "probecast/codec/crc32c.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/record.h"

namespace probecast::bus {
namespace {

static_assert(std::endian::native == std::endian::little, "the bus format is written with little-endian stores");

constexpr uint8_t kMagic[4] = {'P', 'C', 'B', 'M'};

void put(std::vector<uint8_t>& out, const void* v, size_t n) {
  const auto* p = static_cast<const uint8_t*>(v);
  out.insert(out.end(), p, p + n);
}
template <typename T>
void put(std::vector<uint8_t>& out, T v) {
  put(out, &v, sizeof v);
}
template <typename T>
T get(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void writeHeader(Kind kind, uint16_t flags, std::vector<uint8_t>& out) {
  out.clear();
  put(out, kMagic, 4);
  put(out, kBusVersion);
  put(out, static_cast<uint8_t>(kind));
  put(out, flags);
  put(out, uint32_t{0});  // body size and checksum, once the body is written
  put(out, uint32_t{0});
}

void finish(std::vector<uint8_t>& out) {
  const auto body = static_cast<uint32_t>(out.size() - kHeaderSize);
  std::memcpy(out.data() + 8, &body, 4);
  uint32_t crc = crc32c(out.data(), 12);
  crc = crc32c(out.data() + kHeaderSize, body, crc);
  std::memcpy(out.data() + 12, &crc, 4);
}

void writeVolume(const Volume& v, std::vector<uint8_t>& out) {
  put(out, v.epoch);
  put(out, v.publishedUs);
  put(out, kFormatVersion);
  put(out, static_cast<uint8_t>(v.layout.repr));
  put(out, v.layout.brickDim);
  put(out, static_cast<uint8_t>(v.offsets.empty() && !v.hasOffsets ? 0 : 1));
  for (uint16_t n : v.layout.grid) put(out, n);
  put(out, uint16_t{0});
  for (float f : v.bounds.min) put(out, f);
  for (float f : v.bounds.max) put(out, f);
  put(out, v.offsets.empty() ? v.offsetsCrc : offsetsChecksum(v.offsets));
  put(out, v.areaLights.version);
  put(out, v.areaLights.minPowerFraction);
  put(out, v.sceneHash.data(), v.sceneHash.size());
}

void writeState(const SceneState& st, std::vector<uint8_t>& out) {
  put(out, st.time);
  put(out, st.rate);
  put(out, st.clockUs);
  put(out, static_cast<uint32_t>(st.lights.size()));
  for (const LightState& l : st.lights) {
    put(out, l.type);
    for (float f : l.position) put(out, f);
    for (float f : l.direction) put(out, f);
    for (float f : l.color) put(out, f);
    put(out, l.intensity);
    put(out, l.range);
    put(out, l.innerCone);
    put(out, l.outerCone);
  }
}

// The state at `p` within `bytes`; `used` is its size.
bool readState(const uint8_t* p, size_t bytes, SceneState& st, size_t& used, std::string& why) {
  if (bytes < kStateFixedSize) return why = "brick message truncated in its scene state", false;
  st.time = get<double>(p);
  st.rate = get<double>(p + 8);
  st.clockUs = get<uint64_t>(p + 16);
  const uint32_t n = get<uint32_t>(p + 24);
  if (n > kMaxStateLights)
    return why = "scene state with " + std::to_string(n) + " lights (at most " + std::to_string(kMaxStateLights) + ")",
           false;
  used = kStateFixedSize + static_cast<size_t>(n) * kLightStateSize;
  if (bytes < used) return why = "brick message truncated in its scene state's lights", false;
  st.lights.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    const uint8_t* q = p + kStateFixedSize + i * kLightStateSize;
    LightState& l = st.lights[i];
    l.type = get<uint32_t>(q);
    for (int a = 0; a < 3; ++a) {
      l.position[a] = get<float>(q + 4 + 4 * a);
      l.direction[a] = get<float>(q + 16 + 4 * a);
      l.color[a] = get<float>(q + 28 + 4 * a);
    }
    l.intensity = get<float>(q + 40);
    l.range = get<float>(q + 44);
    l.innerCone = get<float>(q + 48);
    l.outerCone = get<float>(q + 52);
  }
  return checkSceneState(st, why);
}

bool readVolume(const uint8_t* p, Volume& v, std::string& why) {
  v.epoch = get<uint64_t>(p);
  v.publishedUs = get<uint64_t>(p + 8);
  if (v.epoch == 0) return why = "stream epoch 0 (no epoch)", false;
  if (p[16] != kFormatVersion)
    return why = "codec format version " + std::to_string(p[16]) + ", this build reads " +
                 std::to_string(kFormatVersion), false;
  if (!isValidRepresentation(p[17])) return why = "unknown representation " + std::to_string(p[17]), false;
  if (p[19] > 1) return why = "volume offsets flag " + std::to_string(p[19]) + " is neither 0 nor 1", false;
  if (get<uint16_t>(p + 26) != 0) return why = "reserved volume bytes are not 0", false;
  v.hasOffsets = p[19] == 1;
  v.offsetsCrc = get<uint32_t>(p + 52);
  v.offsets.clear();
  if (!v.hasOffsets && v.offsetsCrc != 0) return why = "a volume without offsets announces an offsets checksum", false;
  v.areaLights = {get<uint32_t>(p + 56), get<float>(p + 60)};
  std::memcpy(v.sceneHash.data(), p + 64, 32);
  v.sceneManifest.clear();
  if (!checkAreaLightRule(v.areaLights, why)) return false;
  v.layout.repr = static_cast<Representation>(p[17]);
  v.layout.brickDim = p[18];
  for (int a = 0; a < 3; ++a) v.layout.grid[a] = get<uint16_t>(p + 20 + 2 * a);
  if (!isValidLayout(v.layout))
    return why = "volume layout " + std::to_string(v.layout.grid[0]) + "x" + std::to_string(v.layout.grid[1]) + "x" +
                 std::to_string(v.layout.grid[2]) + " in bricks of " + std::to_string(v.layout.brickDim) +
                 " is not valid", false;
  for (int a = 0; a < 3; ++a) {
    v.bounds.min[a] = get<float>(p + 28 + 4 * a);
    v.bounds.max[a] = get<float>(p + 40 + 4 * a);
    if (!std::isfinite(v.bounds.min[a]) || !std::isfinite(v.bounds.max[a]))
      return why = "volume bounds are not finite", false;
  }
  return true;
}

// One section of the brick's version, of the given kind, exactly filling `bytes`.
bool checkSection(const StreamLayout& layout, std::span<const uint8_t> bytes, const Brick& b, SectionKind kind,
                  std::string& why) {
  const char* name = kind == SectionKind::Keyframe ? "keyframe" : "delta";
  SectionInfo info;
  if (CodecStatus st = readSection(layout, bytes.data(), bytes.size(), &info); st != CodecStatus::Ok)
    return why = std::string(name) + " section: " + codecStatusName(st), false;
  if (info.bytes != bytes.size())
    return why = std::string(name) + " section of " + std::to_string(info.bytes) + " bytes in a field of " +
                 std::to_string(bytes.size()), false;
  if (info.kind != kind) return why = std::string(name) + " field holds another kind of section", false;
  if (info.brick != b.brick || info.version != b.version)
    return why = std::string(name) + " section is brick " + std::to_string(info.brick) + " version " +
                 std::to_string(info.version) + ", the message brick " + std::to_string(b.brick) + " version " +
                 std::to_string(b.version), false;
  return true;
}

// The offsets that follow a volume message's fixed part: as many as the volume announces, valid,
// with the announced checksum.
bool readOffsets(const uint8_t* p, size_t bytes, Volume& v, std::string& why) {
  const uint64_t probes = static_cast<uint64_t>(v.layout.grid[0]) * v.layout.grid[1] * v.layout.grid[2];
  const uint64_t expected = v.hasOffsets ? probes * kOffsetBytesPerProbe : 0;
  if (bytes != expected)
    return why = "volume message has " + std::to_string(bytes) + " offset bytes, its volume " +
                 std::to_string(expected), false;
  if (!v.hasOffsets) return true;
  const auto* q = reinterpret_cast<const int8_t*>(p);
  std::vector<float> metres;
  if (!dequantizeProbeOffsets(gridOf(v.layout, v.bounds), q, bytes, metres, why)) return false;
  v.offsets.assign(q, q + bytes);
  if (offsetsChecksum(v.offsets) != v.offsetsCrc) return why = "volume offsets do not match their checksum", false;
  return true;
}

}  // namespace

bool checkSceneState(const SceneState& st, std::string& why) {
  if (!std::isfinite(st.time)) return why = "scene time is not finite", false;
  if (!std::isfinite(st.rate) || std::fabs(st.rate) > kMaxSceneRate)
    return why = "scene playback rate is not a finite value within +-1000", false;
  if (st.lights.size() > kMaxStateLights) return why = "scene state has more than 64 lights", false;
  for (size_t i = 0; i < st.lights.size(); ++i) {
    const LightState& l = st.lights[i];
    const std::string which = "scene light " + std::to_string(i);
    if (l.type > 2) return why = which + " is of unknown type " + std::to_string(l.type), false;
    float len2 = 0.0f;
    bool finite = std::isfinite(l.intensity) && std::isfinite(l.range) && std::isfinite(l.innerCone) &&
                  std::isfinite(l.outerCone);
    for (int a = 0; a < 3; ++a) {
      finite = finite && std::isfinite(l.position[a]) && std::isfinite(l.direction[a]) && std::isfinite(l.color[a]);
      len2 += l.direction[a] * l.direction[a];
      if (l.color[a] < 0.0f) return why = which + " has a negative colour", false;
    }
    if (!finite) return why = which + " holds NaN or Inf", false;
    if (l.intensity < 0.0f || l.range < 0.0f) return why = which + " has a negative intensity or range", false;
    if (std::fabs(len2 - 1.0f) > 2e-3f) return why = which + "'s direction is not unit length", false;
    if (l.innerCone < 0.0f || l.outerCone > 1.5707964f || l.innerCone > l.outerCone)
      return why = which + "'s cone angles are not 0 <= inner <= outer <= pi/2", false;
  }
  return true;
}

uint32_t offsetsChecksum(const std::vector<int8_t>& offsets) {
  return offsets.empty() ? 0 : crc32c(reinterpret_cast<const uint8_t*>(offsets.data()), offsets.size());
}

void writeVolumeMessage(const Volume& volume, uint16_t flags, std::vector<uint8_t>& out) {
  writeHeader(Kind::Volume, flags, out);
  writeVolume(volume, out);
  put(out, static_cast<uint32_t>(volume.sceneManifest.size()));
  put(out, volume.sceneManifest.data(), volume.sceneManifest.size());
  put(out, volume.offsets.data(), volume.offsets.size());
  finish(out);
}

void writeBrickMessage(const Volume& volume, const Brick& brick, uint16_t flags, std::vector<uint8_t>& out) {
  writeHeader(Kind::Brick, flags, out);
  writeVolume(volume, out);
  put(out, brick.brick);
  put(out, brick.version);
  put(out, brick.producerFrame);
  put(out, brick.change);
  put(out, static_cast<uint32_t>(brick.keyframe.size()));
  put(out, static_cast<uint32_t>(brick.delta.size()));
  writeState(brick.state, out);
  put(out, brick.keyframe.data(), brick.keyframe.size());
  put(out, brick.delta.data(), brick.delta.size());
  finish(out);
}

bool readMessage(const uint8_t* data, size_t size, Message& out, std::string& why) {
  if (size < kHeaderSize)
    return why = "truncated: " + std::to_string(size) + " bytes, a bus message has at least " +
                 std::to_string(kHeaderSize), false;
  if (std::memcmp(data, kMagic, 4) != 0) return why = "not a probe bus message (bad magic)", false;
  if (data[4] != kBusVersion)
    return why = "bus format version " + std::to_string(data[4]) + ", this build reads " +
                 std::to_string(kBusVersion), false;
  if (data[5] != static_cast<uint8_t>(Kind::Volume) && data[5] != static_cast<uint8_t>(Kind::Brick))
    return why = "unknown message kind " + std::to_string(data[5]), false;
  out.kind = static_cast<Kind>(data[5]);
  out.flags = get<uint16_t>(data + 6);
  if (out.flags & ~kEndOfBatch) return why = "unknown flags " + std::to_string(out.flags), false;
  const uint64_t body = get<uint32_t>(data + 8);
  if (body != size - kHeaderSize)
    return why = "header announces " + std::to_string(body) + " body bytes, the message has " +
                 std::to_string(size - kHeaderSize), false;
  uint32_t crc = crc32c(data, 12);
  crc = crc32c(data + kHeaderSize, size - kHeaderSize, crc);
  if (crc != get<uint32_t>(data + 12)) return why = "checksum mismatch", false;

  const uint8_t* p = data + kHeaderSize;
  const size_t fixed = out.kind == Kind::Volume ? kVolumeSize : kVolumeSize + kBrickFixedSize;
  if (body < fixed)
    return why = "body of " + std::to_string(body) + " bytes, a " +
                 (out.kind == Kind::Volume ? "volume message has " : "brick message has ") + "at least " +
                 std::to_string(fixed), false;
  if (!readVolume(p, out.volume, why)) return false;
  if (out.kind == Kind::Volume) {
    if (body < kVolumeSize + 4) return why = "volume message truncated before its scene manifest", false;
    const uint64_t manifestBytes = get<uint32_t>(p + kVolumeSize);
    if (manifestBytes > kMaxSceneManifestBytes || manifestBytes > body - kVolumeSize - 4)
      return why = "volume message announces a scene manifest of " + std::to_string(manifestBytes) +
                   " bytes in a body of " + std::to_string(body), false;
    if ((manifestBytes == 0) != !out.volume.hasScene())
      return why = "volume message has a scene hash without a manifest, or a manifest without a hash", false;
    out.volume.sceneManifest.assign(reinterpret_cast<const char*>(p + kVolumeSize + 4), manifestBytes);
    const size_t offsetsAt = kVolumeSize + 4 + manifestBytes;
    return readOffsets(p + offsetsAt, body - offsetsAt, out.volume, why);
  }

  p += kVolumeSize;
  Brick& b = out.brick;
  b.brick = get<uint32_t>(p);
  b.version = get<uint32_t>(p + 4);
  b.producerFrame = get<uint32_t>(p + 8);
  b.change = get<float>(p + 12);
  const uint64_t keyBytes = get<uint32_t>(p + 16), deltaBytes = get<uint32_t>(p + 20);
  const StreamLayout& layout = out.volume.layout;
  if (b.brick >= brickCount(layout))
    return why = "brick " + std::to_string(b.brick) + " outside the volume's " + std::to_string(brickCount(layout)),
           false;
  if (b.version == 0) return why = "brick version 0 (nothing) is never published", false;
  if (!std::isfinite(b.change) || b.change < 0.0f || b.change > kMaxChange)
    return why = "brick change is not a finite value in [0, 1e6]", false;
  p += kBrickFixedSize;
  size_t stateBytes = 0;
  if (!readState(p, body - fixed, b.state, stateBytes, why)) return false;
  if (keyBytes + deltaBytes != body - fixed - stateBytes)
    return why = "sections of " + std::to_string(keyBytes) + " + " + std::to_string(deltaBytes) + " bytes in " +
                 std::to_string(body - fixed - stateBytes) + " bytes", false;
  p += stateBytes;
  b.keyframe = {p, static_cast<size_t>(keyBytes)};
  b.delta = {p + keyBytes, static_cast<size_t>(deltaBytes)};
  if (!checkSection(layout, b.keyframe, b, SectionKind::Keyframe, why)) return false;
  if (!b.delta.empty() && !checkSection(layout, b.delta, b, SectionKind::Delta, why)) return false;
  return true;
}

}  // namespace probecast::bus
