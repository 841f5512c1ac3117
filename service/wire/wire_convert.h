// Conversions between the protocol's messages and the codec's types (private to the service).
#pragma once

#include <string>
#include <vector>

#include "probecast.pb.h"
#include "probecast/codec/priority.h"
#include "probecast/codec/stream.h"
#include "probecast/service/bus_format.h"

namespace probecast::service {

// 2: VolumeDescription.probe_offsets; 3: area_light_rule; 4: the scene (hash, manifest, state, GetScene)
constexpr uint32_t kProtocolVersion = 4;
extern const char* const kShConvention;

// The hub's volume (bus_format.h): layout, bounds, epoch, quantised offsets and area light rule.
void volumeToWire(const bus::Volume& volume, v1::VolumeDescription& out);
// Validates a volume description from a server, its probe offsets (returned in metres, empty for
// none), area light rule and scene (a 32-byte hash with its manifest, or neither; the hash is the
// caller's to check) too; `why` says what is wrong.
bool volumeFromWire(const v1::VolumeDescription& in, StreamLayout& layout, GridBounds& bounds,
                    std::vector<float>& offsets, AreaLightRule& areaLights, SceneStamp& scene, std::string& why);
// The digest a resuming client names its held description by (Hello.held_description): SHA-256
// of the probe offsets and the scene manifest, each after its length as 8 bytes little-endian.
std::string descriptionDigest(const std::string& probeOffsets, const std::string& sceneManifest);
void stateToWire(const bus::SceneState& in, v1::SceneState& out);
// Checks a frame's scene state (bus::checkSceneState, 3 floats per light vector).
bool stateFromWire(const v1::SceneState& in, bus::SceneState& out, std::string& why);
// Validates and converts views: count, 16 finite matrix entries each, finite eyes.
bool viewsFromWire(const v1::ViewUpdate& in, uint32_t maxViews, std::vector<View>& out, std::string& why);
void viewsToWire(const std::vector<View>& views, v1::ViewUpdate& out);

// A ServerMessage holding one Frame, written by hand around a payload the caller writes in place,
// so that a frame's sections are copied once on their way to the transport. The bytes are those
// protobuf writes for the same message (fields in number order, proto3 zeros left out).
struct FrameFields {
  uint32_t sequence = 0;
  uint64_t serverTimeUs = 0;
  size_t payloadBytes = 0;
  uint32_t keyframes = 0;
  uint32_t deltas = 0;
  const std::string* sceneState = nullptr;  // a serialised SceneState (null: the field is left out)
  uint64_t sentUs = 0;
};
// Bytes before the payload and after it.
size_t framePrefixBytes(const FrameFields& f);
size_t frameSuffixBytes(const FrameFields& f);
// Write them; each returns the end of what it wrote (writeFramePrefix: where the payload goes).
uint8_t* writeFramePrefix(const FrameFields& f, uint8_t* out);
uint8_t* writeFrameSuffix(const FrameFields& f, uint8_t* out);

}  // namespace probecast::service
