// Where a hub's brick versions come from (private to the hub): its own encoder (a producer) or
// messages off the bus (an edge). The hub calls a source under its own lock only; everything
// per subscriber stays in the hub.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "probecast/codec/probe_volume.h"
#include "probecast/codec/stream.h"
#include "probecast/service/bus_format.h"

namespace probecast::service {

class BrickSource {
 public:
  virtual ~BrickSource() = default;
  virtual uint32_t version(uint32_t brick) const = 0;
  // As StreamEncoder::changeSince: 0 when current, 1 when nothing is held or the history is too short.
  virtual float changeSince(uint32_t brick, uint32_t held) const = 0;
  // What a holder of `held` needs: empty if current, the delta when one behind and one is known,
  // a keyframe otherwise; `delta` (when given) says which.
  virtual std::span<const uint8_t> sectionFor(uint32_t brick, uint32_t held, bool* delta = nullptr) = 0;
  // The volume a subscriber that holds every current version decodes.
  virtual void copyVolume(const GridBounds& bounds, ProbeVolume& out) const = 0;
};

// A producer's source: the hub's own encoder.
class EncoderBricks : public BrickSource {
 public:
  EncoderBricks(const StreamLayout& layout, const EncoderOptions& options) : encoder_(layout, options) {}
  uint32_t version(uint32_t brick) const override { return encoder_.brickVersion(brick); }
  float changeSince(uint32_t brick, uint32_t held) const override { return encoder_.changeSince(brick, held); }
  std::span<const uint8_t> sectionFor(uint32_t brick, uint32_t held, bool* delta = nullptr) override {
    if (delta) *delta = held + 1 == encoder_.brickVersion(brick) && !encoder_.deltaIsKeyframe(brick);
    return encoder_.sectionFor(brick, held);
  }
  void copyVolume(const GridBounds& bounds, ProbeVolume& out) const override { encoder_.copyVolume(bounds, out); }
  StreamEncoder& encoder() { return encoder_; }

 private:
  StreamEncoder encoder_;
};

// A coarser representation of another source's volume (a subscriber asked for less than the
// stream carries): the hub's own encoder of that representation, fed the volume a holder of every
// current version of the primary decodes (follow). Its versions are its own, numbered by this
// hub alone, so they come with an epoch of their own (a resume elsewhere starts from keyframes).
class TranscodedBricks final : public EncoderBricks {
 public:
  TranscodedBricks(const StreamLayout& layout, const EncoderOptions& options, uint64_t epoch)
      : EncoderBricks(layout, options), epoch_(epoch) {}
  // Encodes the primary's current volume; returns the bricks given a new version.
  uint32_t follow(const BrickSource& primary, const GridBounds& bounds) {
    primary.copyVolume(bounds, volume_);
    return encoder().update(volume_.probes.data(), volume_.active.data());
  }
  uint64_t epoch() const { return epoch_; }

 private:
  uint64_t epoch_;
  ProbeVolume volume_;  // the primary's, reused
};

// An edge's source: the newest version of each brick as the bus delivered it. Every message's
// keyframe is decoded before it is kept, and its delta applied to the previous version and
// compared with the keyframe, so nothing a subscriber is sent is unchecked. A delta that cannot
// be checked (the previous version never arrived here) or does not match is dropped: holders of
// the previous version then get the keyframe.
class BusBricks final : public BrickSource {
 public:
  explicit BusBricks(const StreamLayout& layout);
  enum class Accepted { Applied, Stale, Refused };
  // A brick message of this source's layout. Stale: a version not newer than the one held (a
  // redelivery). Refused (`why` says why, nothing changed): its keyframe does not decode. Applied
  // with `why` set: kept, but its delta was refused and dropped.
  Accepted accept(const bus::Brick& brick, std::string& why);

  uint32_t version(uint32_t brick) const override { return bricks_[brick].version; }
  float changeSince(uint32_t brick, uint32_t held) const override;
  std::span<const uint8_t> sectionFor(uint32_t brick, uint32_t held, bool* delta = nullptr) override;
  void copyVolume(const GridBounds& bounds, ProbeVolume& out) const override { mirror_.copyVolume(bounds, out); }

 private:
  static constexpr uint32_t kHistory = 16;
  struct Brick {
    uint32_t version = 0;
    std::vector<uint8_t> keyframe, delta;
    bool deltaIsKeyframe = false;    // the version changed the brick's representation
    float change[kHistory] = {};     // change of version v at v % kHistory
    uint32_t knownSince = UINT32_MAX;  // the first version whose change is known here
  };
  bool agree(uint32_t brick);

  StreamLayout layout_;
  std::vector<Brick> bricks_;
  StreamDecoder mirror_;   // every brick at its newest version, from keyframes
  StreamDecoder scratch_;  // the same state reached through deltas where they are checked
  std::vector<uint8_t> frame_;
  std::vector<uint32_t> indices_;
};

}  // namespace probecast::service
