// One probe volume along the whole path: what the updater traces, the hub publishes, a client's
// snapshot holds, the raster client uploads and probe files store.
//
// Grid: dims[0] × dims[1] × dims[2] probes, probe (x, y, z) at index x + nx (y + ny z), spaced
// evenly from bounds.min (probe (0, 0, 0)) to bounds.max (probe (nx-1, ny-1, nz-1)), metres; an
// axis of one probe puts it midway. Samples: 27 floats per probe in the sh.h layout (L2 SH of
// incident radiance, coefficient-major RGB, no Condon-Shortley phase) and one active byte per
// probe (1 = active, 0 = inside geometry: never sent, never interpolated from).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "probecast/codec/record.h"

namespace probecast {

struct GridBounds {
  float min[3] = {0, 0, 0};  // position of probe (0, 0, 0), metres
  float max[3] = {1, 1, 1};  // position of probe (nx-1, ny-1, nz-1)
};

struct ProbeGrid {
  uint32_t dims[3] = {4, 4, 4};  // probes along x, y, z
  GridBounds bounds{{-1, -1, -1}, {1, 1, 1}};
  uint32_t count() const { return dims[0] * dims[1] * dims[2]; }
  // Position of the probe at `index`, metres.
  void position(uint32_t index, float out[3]) const;
};

// The default grid over a box [lo, hi] (a scene's bounds): the probes sit at the centres of the
// cells of a dims[0] × dims[1] × dims[2] grid over the box, half a cell in from every face.
ProbeGrid cellCentredGrid(const uint32_t dims[3], const float lo[3], const float hi[3]);

// Which emitters the probes leave out for every viewer to light itself (client area lights,
// scene/area_lights.h), stated by the producer so that a viewer applies the same rule: light is
// then neither counted twice nor lost. version 0: none, the probes hold every emitter (and
// minPowerFraction is 0). kAreaLightRuleVersion: area_lights.h's rule as this build has it (constant
// emission only, at most 8 lights and 64 triangles) with the threshold minPowerFraction in [0, 1].
// A new rule gets a new version; a viewer refuses one it does not know.
constexpr uint32_t kAreaLightRuleVersion = 1;
struct AreaLightRule {
  uint32_t version = 0;
  float minPowerFraction = 0.0f;  // share of the scene's emitted power an emitter needs
  bool on() const { return version != 0; }
  bool operator==(const AreaLightRule&) const = default;
};
// The rule above: version 0 with threshold 0, or kAreaLightRuleVersion with a threshold in [0, 1].
// False with the reason in `error`.
bool checkAreaLightRule(const AreaLightRule& rule, std::string& error);

// The scene a volume was traced in: its package's hash and manifest (service/scene_package.h: the
// scene with every file it uses, and the distant light around it) and the scene time, seconds.
// An empty manifest: unknown (a volume made before scenes were named, or generated in code).
constexpr size_t kMaxSceneManifestBytes = 256 * 1024;
struct SceneStamp {
  std::array<uint8_t, 32> hash{};  // SHA-256 of the manifest
  std::string manifest;
  double time = 0.0;
  bool known() const { return !manifest.empty(); }
  bool operator==(const SceneStamp&) const = default;
};

struct ProbeVolume {
  ProbeGrid grid;
  std::vector<float> probes;    // 27 floats per probe
  std::vector<uint8_t> active;  // one per probe, 1 = active
  // What the samples are: float L2 as traced (nullopt), or what records of this representation
  // decode to (decodeAs, a stream decoder).
  std::optional<Representation> decodedFrom;
  // zh3h only: the renderer hallucinates ZH3 per pixel after interpolating (interpolate, then
  // hallucinate) and adds it to the interpolated L2 band, which holds 0 for a probe that
  // hallucinates and minus its own hallucinated band for one the encoder kept at plain L1 (so at
  // the probe the two cancel). False: the L2 band holds what the codec decoded (for zh3h,
  // hallucinated per probe or plain L1). Same name and meaning in ClientConfig, StreamDecoder and
  // decodeProbeRecord.
  bool zh3PerPixel = false;
  uint32_t updates = 0;          // updates accumulated into the samples (0 = unknown)
  uint32_t samplesPerProbe = 0;  // paths per probe per update (0 = unknown)
  // Monte Carlo noise of the samples: per probe, the standard error of the luminance of c00
  // (Rec. 709 weights, same radiance units as the samples); every other coefficient of a traced
  // probe has about the same standard error (for noise uncorrelated with direction, every
  // orthonormal SH coefficient's estimator has the same variance). Empty when unknown; 0 for
  // inactive probes. A stream encoder with a noise scale does not re-send changes within it.
  std::vector<float> noise;
  // How long each probe's light has held still: updates since the scene last changed what may light
  // it (the updater cannot tell which probes a change reaches, so a change counts for all of them;
  // restarts, which noise causes too, do not count). Empty when unknown; 0 for inactive probes. A
  // stream encoder with a refinement interval holds back refinements only of probes still for the
  // whole interval (EncoderOptions::refinementInterval).
  std::vector<uint32_t> stillUpdates;
  // Relocation: per probe, 3 floats (x, y, z) in metres added to grid.position(i), the position the
  // probe is traced at and interpolated from; empty = every probe at its grid position.
  std::vector<float> offsets;
  // The emitters these probes leave out (none unless the producer says so).
  AreaLightRule areaLights;
  // The scene and time the samples were traced in.
  SceneStamp scene;

  uint32_t count() const { return grid.count(); }
};

// An empty volume of `grid` (every probe zero and active).
ProbeVolume makeProbeVolume(const ProbeGrid& grid);

// Checks what every consumer relies on: 1 to kMaxGridDim probes per axis and at most kMaxProbes,
// finite bounds with max > min along every axis of two or more probes, 27 floats and one active
// byte (0 or 1) per probe, every coefficient finite, `noise` empty or one finite value >= 0 per
// probe, `stillUpdates` empty or one per probe, `offsets` empty or 3 finite floats per probe, each
// within half a cell on its axis (probeCellSize; 0 along an axis of one probe), and `areaLights` valid (checkAreaLightRule). False with the reason in `error`.
bool checkProbeVolume(const ProbeVolume& volume, std::string& error);

// The volume as a viewer holds it after the codec: every probe through a `repr` record and back
// (inactive probes too, as the raster client fills them from neighbours anyway). For zh3h,
// `zh3PerPixel` chooses the renderer's per-pixel form (true, as the raster client draws zh3h) or
// the per-probe result.
ProbeVolume decodeAs(const ProbeVolume& volume, Representation repr, bool zh3PerPixel);

// A fingerprint of what a viewer lights with: CRC-32C over the samples (27 floats per probe, as
// little-endian bytes), the active bytes and the offsets (3 floats per probe, or none). Two decoders
// of one stream (the native client, the browser's WebAssembly build) that hold the same versions
// agree on it.
uint32_t volumeChecksum(const ProbeVolume& volume);

}  // namespace probecast
