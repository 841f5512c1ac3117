// An edge hub's brick versions, from bus messages, each checked by decoding before it is kept.
#include <algorithm>
#include <cstring>

#include "brick_source.h"

namespace probecast::service {

BusBricks::BusBricks(const StreamLayout& layout)
    : layout_(layout), bricks_(brickCount(layout)), mirror_(layout), scratch_(layout) {}

bool BusBricks::agree(uint32_t brick) {
  indices_.resize(brickProbeCount(layout_, brick));
  brickProbeIndices(layout_, brick, indices_.data());
  for (uint32_t p : indices_) {
    if (mirror_.activeMask()[p] != scratch_.activeMask()[p]) return false;
    if (std::memcmp(mirror_.probes() + static_cast<size_t>(p) * kProbeFloats,
                    scratch_.probes() + static_cast<size_t>(p) * kProbeFloats, kProbeFloats * sizeof(float)) != 0)
      return false;
  }
  return true;
}

BusBricks::Accepted BusBricks::accept(const bus::Brick& b, std::string& why) {
  why.clear();
  Brick& held = bricks_[b.brick];
  if (b.version <= held.version) return Accepted::Stale;
  const std::span<const uint8_t> key[] = {b.keyframe};
  writeFrame(layout_, b.version, key, frame_);
  if (CodecStatus st = mirror_.apply(frame_.data(), frame_.size()); st != CodecStatus::Ok)
    return why = std::string("keyframe does not decode: ") + codecStatusName(st), Accepted::Refused;
  // The delta is checked where the previous version was reached the same way; a mismatch puts
  // the keyframe there too, so both decoders agree again.
  bool deltaOk = false;
  if (!b.delta.empty() && scratch_.brickVersion(b.brick) + 1 == b.version) {
    const std::span<const uint8_t> delta[] = {b.delta};
    writeFrame(layout_, b.version, delta, frame_);
    const CodecStatus st = scratch_.apply(frame_.data(), frame_.size());
    deltaOk = st == CodecStatus::Ok && agree(b.brick);
    if (!deltaOk)
      why = st != CodecStatus::Ok ? std::string("delta dropped, it does not decode: ") + codecStatusName(st)
                                  : "delta dropped, it does not reach the keyframe's probes";
  }
  if (!deltaOk) {
    writeFrame(layout_, b.version, key, frame_);
    scratch_.apply(frame_.data(), frame_.size());  // decoded above, so it applies
  }
  if (held.version + 1 != b.version) held.knownSince = b.version;  // versions in between never arrived
  else if (held.knownSince == UINT32_MAX) held.knownSince = b.version;
  held.version = b.version;
  held.keyframe.assign(b.keyframe.begin(), b.keyframe.end());
  if (deltaOk) held.delta.assign(b.delta.begin(), b.delta.end());
  else held.delta.clear();
  SectionInfo info;
  held.deltaIsKeyframe = deltaOk && readSection(layout_, b.delta.data(), b.delta.size(), &info) == CodecStatus::Ok &&
                         info.kind == SectionKind::Keyframe;
  held.change[b.version % kHistory] = b.change;
  return Accepted::Applied;
}

float BusBricks::changeSince(uint32_t brick, uint32_t heldVersion) const {
  const Brick& b = bricks_[brick];
  if (heldVersion >= b.version) return 0.0f;
  if (heldVersion == 0 || b.version - heldVersion > kHistory || heldVersion + 1 < b.knownSince) return 1.0f;
  float sum = 0.0f;
  for (uint32_t v = heldVersion + 1; v <= b.version; ++v) sum += b.change[v % kHistory];
  return sum;
}

std::span<const uint8_t> BusBricks::sectionFor(uint32_t brick, uint32_t heldVersion, bool* delta) {
  const Brick& b = bricks_[brick];
  const bool useDelta = heldVersion + 1 == b.version && !b.delta.empty();
  if (delta) *delta = useDelta && !b.deltaIsKeyframe;
  if (heldVersion == b.version) return {};
  return useDelta ? std::span<const uint8_t>(b.delta) : std::span<const uint8_t>(b.keyframe);
}

}  // namespace probecast::service
