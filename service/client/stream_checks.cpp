#include "stream_checks.h"

#include <algorithm>

#include "probecast/service/scene_package.h"
#include "wire_convert.h"

namespace probecast::service {

namespace {

// The sections a frame claims (Frame.keyframes, deltas) against those its payload holds: a frame
// holding that many sections (the decoder checks the rest). The kinds are the server's account: a
// delta in another representation than the brick's last travels as a keyframe.
bool countsMatch(const v1::Frame& f, std::string& why) {
  FrameHeader header;
  const CodecStatus st = verifyFrame(reinterpret_cast<const uint8_t*>(f.payload().data()), f.payload().size(), &header);
  if (st != CodecStatus::Ok) return why = std::string("its payload is no frame: ") + codecStatusName(st), false;
  if (uint64_t{f.keyframes()} + f.deltas() != header.sectionCount)
    return why = "it claims " + std::to_string(f.keyframes()) + " keyframes and " + std::to_string(f.deltas()) +
                 " deltas, its payload holds " + std::to_string(header.sectionCount) + " sections", false;
  return true;
}

}  // namespace

Verdict checkDescription(const v1::VolumeDescription& in, const ClientConfig& config, Description& out,
                         std::string& why) {
  Description d;
  if (!volumeFromWire(in, d.layout, d.bounds, d.offsets, d.areaLights, d.scene, why))
    return why = "bad volume description: " + why, Verdict::Retry;
  if (d.scene.known()) {
    ScenePackage named;
    if (sha256(d.scene.manifest) != d.scene.hash)
      return why = "bad volume description: its scene manifest does not match its hash", Verdict::Retry;
    if (!parseManifest(d.scene.manifest, named, why)) return why = "bad volume description: " + why, Verdict::Retry;
  }
  const uint64_t probes = uint64_t{d.layout.grid[0]} * d.layout.grid[1] * d.layout.grid[2];
  if (probes > config.maxProbes)
    return why = "the volume description holds " + std::to_string(probes) + " probes, more than the " +
                 std::to_string(config.maxProbes) + " this client accepts", Verdict::ForGood;
  if (config.scene && (!d.scene.known() || d.scene.hash != *config.scene))
    return why = "the stream names scene " + (d.scene.known() ? shortHex(d.scene.hash) : std::string("(none)")) +
                 ", not the scene " + shortHex(*config.scene) + " its description named before; this viewer "
                 "draws that one and stops", Verdict::ForGood;
  if (config.representation && d.layout.repr != *config.representation)
    return why = std::string("the server streams ") + representationName(d.layout.repr) + ", not the " +
                 representationName(*config.representation) + " asked for", Verdict::Retry;
  d.epoch = in.stream_epoch();
  out = std::move(d);
  return Verdict::Accept;
}

bool checkFrame(const v1::Frame& in, bus::SceneState& state, std::string& why) {
  if (in.has_scene_state() && !stateFromWire(in.scene_state(), state, why)) return why = "frame refused: " + why, false;
  if (!countsMatch(in, why)) return why = "frame refused: " + why, false;
  return true;
}

}  // namespace probecast::service
