// The probe bus format: how a producer hands brick versions to a message system (NATS JetStream)
// for stateless edge servers. It is ours, not the message system's: versioned, little-endian,
// checksummed, and parsed by a decoder that checks every size before it reads (codec and std only,
// so the fuzz build links it).
//
// Every brick message is self-contained: it carries the volume it belongs to (epoch, layout,
// bounds, a checksum of the probe offsets, the client area light rule and the scene's hash), the
// scene state its lighting was traced in, and both sections of the new version, its keyframe and
// its delta from the version before. A store that keeps only the newest message per brick
// therefore holds everything a late joiner needs but the offsets (3 bytes per probe) and the
// scene's manifest, which travel once, in the volume message; a holder one version behind still
// gets the small delta.
//
// Message = header (16 bytes) + body, little-endian:
//   header: magic "PCBM" | u8 busVersion (4) | u8 kind (1 volume, 2 brick) | u16 flags
//           | u32 bodyBytes | u32 CRC-32C of the preceding 12 bytes and the body
//   volume: u64 epoch (nonzero) | u64 publishedUs | u8 codecFormatVersion (stream.h kFormatVersion)
//           | u8 representation | u8 brickDim | u8 hasOffsets (0 or 1) | u16 nx, ny, nz
//           | u16 reserved (0) | f32 boundsMin[3] | f32 boundsMax[3]
//           | u32 offsetsCrc (CRC-32C of the offset bytes; 0 without offsets)
//           | u32 areaLightRule | f32 areaLightMin (probe_volume.h AreaLightRule)
//           | u8 sceneHash[32] (SHA-256 of the scene manifest; all 0: no scene named)   (96 bytes)
//           The first part of both messages' bodies. A volume message's body is this, then
//           u32 manifestBytes (0 exactly when the hash is 0; at most 256 KiB) and the scene's
//           manifest (service/scene_package.h), then, with hasOffsets, the offsets: 3 bytes per
//           probe as in probe_offsets.h (int8 steps of 1/256 cell, |q| <= 127, 0 along an axis of
//           one probe).
// Versions 1 to 3 (no offsets, no area light rule, no scene) are refused: producers and edges are
// upgraded together.
//   brick:  u32 brick | u32 version (>= 1) | u32 producerFrame | f32 change (finite, >= 0)
//           | u32 keyframeBytes | u32 deltaBytes  (24 bytes)
//           | state: f64 time | f64 rate | u64 clockUs | u32 lights (at most 64), then per light
//             u32 type (0 point, 1 spot, 2 directional) | f32 position[3] | f32 direction[3]
//             | f32 color[3] | f32 intensity | f32 range | f32 innerCone | f32 outerCone (56 bytes)
//           | keyframe section | delta section
//           Sections exactly as in a codec frame (stream.h); the delta may be absent (0 bytes).
// flags: bit 0 = the last message of a batch the producer published together (receivers may wait
// for it before waking subscribers); other bits must be 0.
// publishedUs: producer wall clock, microseconds since 1970, when the lighting was published.
#pragma once

#include <cstddef>
#include <cstdint>
#include <array>
#include <span>
#include <string>
#include <vector>

#include "probecast/codec/probe_volume.h"
#include "probecast/codec/stream.h"

namespace probecast::bus {

constexpr uint8_t kBusVersion = 4;
constexpr size_t kHeaderSize = 16;
constexpr size_t kVolumeSize = 96;
constexpr size_t kBrickFixedSize = 24;
constexpr size_t kStateFixedSize = 28;
constexpr size_t kLightStateSize = 56;
constexpr uint32_t kMaxStateLights = 64;
// A playback rate beyond this (scene seconds per second) is a broken producer, not an animation.
constexpr double kMaxSceneRate = 1000.0;
constexpr uint16_t kEndOfBatch = 1;
// A brick's relative change above this is nonsense from a broken producer, not lighting.
constexpr float kMaxChange = 1e6f;

enum class Kind : uint8_t { Volume = 1, Brick = 2 };

// A light as a viewer draws it (scene.h Light, in the units of KHR_lights_punctual).
struct LightState {
  uint32_t type = 0;  // 0 point, 1 spot, 2 directional
  float position[3] = {0, 0, 0};
  float direction[3] = {0, -1, 0};  // the way the light travels
  float color[3] = {1, 1, 1};
  float intensity = 1.0f, range = 0.0f, innerCone = 0.0f, outerCone = 0.7853982f;
  bool operator==(const LightState&) const = default;
};

// The state of the scene the lighting was traced in: its clock and what a viewer needs to draw
// direct light at that time. Scene time runs at `rate` scene seconds per second of the producer's
// wall clock from (clockUs, time): a viewer that knows the animation draws at any time from it.
struct SceneState {
  double time = 0.0;     // scene time of the lighting, seconds (finite)
  double rate = 0.0;     // scene seconds per producer second while playing (0: still; |rate| <= kMaxSceneRate)
  uint64_t clockUs = 0;  // producer wall clock (µs since 1970) at which the scene was at `time`
  std::vector<LightState> lights;  // at most kMaxStateLights
  bool operator==(const SceneState&) const = default;
};
// Every number finite, rate within bounds, light types known, intensity, colour and range >= 0,
// cones within [0, pi/2] and inner <= outer, unit-length directions (within 1e-3). False with `why`.
bool checkSceneState(const SceneState& state, std::string& why);

struct Volume {
  uint64_t epoch = 0;  // the producer's stream epoch: brick versions are meaningful within it
  uint64_t publishedUs = 0;
  StreamLayout layout;
  GridBounds bounds;
  // Probe offsets (probe_offsets.h), 3 per probe or none. A parsed brick message leaves them empty
  // and says only whether the volume has some and their checksum; a parsed volume message fills
  // them (checked against both). Writers announce the offsets when there are some, else what
  // hasOffsets and offsetsCrc say (so a parsed brick message is written back as it was); a volume
  // message is written with the offsets it announces, so it needs them.
  std::vector<int8_t> offsets;
  bool hasOffsets = false;
  uint32_t offsetsCrc = 0;
  AreaLightRule areaLights;  // the emitters the probes leave out (checkAreaLightRule)
  // The scene (SceneStamp's hash and manifest): brick messages carry the hash alone, volume
  // messages the manifest too (written as announced; a parsed brick message leaves it empty).
  std::array<uint8_t, 32> sceneHash{};
  std::string sceneManifest;
  bool hasScene() const { return sceneHash != std::array<uint8_t, 32>{}; }
};

// Checksum of offsets as a volume announces them (0 for none).
uint32_t offsetsChecksum(const std::vector<int8_t>& offsets);

struct Brick {
  uint32_t brick = 0;
  uint32_t version = 0;
  uint32_t producerFrame = 0;  // the producer's lighting update that made this version
  float change = 0.0f;         // StreamEncoder::brickChange of this version
  std::span<const uint8_t> keyframe;  // the version's keyframe section
  std::span<const uint8_t> delta;     // its delta section from version - 1; may be empty
  SceneState state;                   // of the producer's frame that made this version
};

struct Message {
  Kind kind = Kind::Volume;
  uint16_t flags = 0;
  Volume volume;
  Brick brick;  // kind Brick: its sections view the parsed bytes
};

// Message for a brick's new version and for the volume description (appended to `out` after clearing it).
void writeVolumeMessage(const Volume& volume, uint16_t flags, std::vector<uint8_t>& out);
void writeBrickMessage(const Volume& volume, const Brick& brick, uint16_t flags, std::vector<uint8_t>& out);

// Parses and checks a message: header, checksum, every size, the volume's layout, the brick's
// index against it and the sections' own headers (brick, version, kind, CRC). False with `why`
// saying what is wrong; `out` is then unspecified. On success out.brick's sections view `data`.
bool readMessage(const uint8_t* data, size_t size, Message& out, std::string& why);

}  // namespace probecast::bus
