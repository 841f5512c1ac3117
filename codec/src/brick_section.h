// Sections: the immutable encoded form of one brick version (private to the codec).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "probe_symbols.h"
#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/status.h"
#include "probecast/codec/stream.h"

namespace probecast {

constexpr uint8_t kCompressionRaw = 0;
constexpr uint8_t kCompressionZstd = 1;
constexpr uint8_t kSectionZstdBit = 0x04;  // format 3 kind byte: the data is a zstd frame without its magic
// The 4 bytes every zstd frame opens with (ZSTD_MAGICNUMBER, little-endian): format 3 leaves them out.
constexpr uint8_t kZstdMagic[4] = {0x28, 0xb5, 0x2f, 0xfd};

// A section's stored zstd data as a zstd frame: format 3 data gets its magic back, in `scratch`.
// parseSection has checked that it is exactly one frame stating the section's raw size.
std::span<const uint8_t> zstdFrameOf(uint8_t formatVersion, const uint8_t* data, size_t size,
                                     std::vector<uint8_t>& scratch);

// Format 3 and 4 delta payloads open with a form byte (stream.h).
constexpr uint8_t kDeltaActiveMask = 0x01;   // an active mask follows; without, the base's is kept
constexpr uint8_t kDeltaChangedList = 0x02;  // changed probes as u8 count + u8 indices, not a mask
constexpr uint8_t kDeltaNarrowWide = 0x04;   // one byte per wide difference (every zig-zag < 256)
constexpr uint8_t kDeltaRice = 0x08;         // format 4: the differences as Rice codes (rice_code.h), not byte planes

inline uint32_t maskBytes(uint32_t probes) { return (probes + 7) / 8; }
inline bool maskBit(const uint8_t* mask, uint32_t i) { return (mask[i >> 3] >> (i & 7)) & 1u; }
inline void setMaskBit(uint8_t* mask, uint32_t i) { mask[i >> 3] = static_cast<uint8_t>(mask[i >> 3] | (1u << (i & 7))); }

// Grid indices of every brick's probes, bricks back to back (brick b owns [first[b], first[b+1])).
struct BrickTable {
  std::vector<uint32_t> probes;
  std::vector<uint32_t> first;
  void build(const StreamLayout& layout);
  uint32_t size(uint32_t brick) const { return first[brick + 1] - first[brick]; }
};

// Largest raw payload any valid section of this brick can have.
size_t maxRawSectionSize(const StreamLayout& layout, uint32_t brick);

// Raw payloads (before compression). `active` has one byte per brick probe (0/1).
void buildKeyframePayload(Representation repr, uint32_t probes, const uint8_t* active, const ProbeSymbols* symbols,
                          std::vector<uint8_t>& out);
// A format 4 delta from (baseActive, base) to (active, next), its differences in byte planes; and,
// when `rice` is given and Rice codes spell them shorter, the same delta with Rice codes there (else
// `rice` is left empty). Which of the two a section stores is the encoder's choice, as compression is.
void buildDeltaPayload(Representation repr, uint32_t probes, const uint8_t* baseActive, const uint8_t* active,
                       const ProbeSymbols* base, const ProbeSymbols* next, std::vector<uint8_t>& out,
                       std::vector<uint8_t>* rice = nullptr);

// Writes a format 3 section (header + possibly compressed payload) into `out`. `zstdContext` is a
// ZSTD_CCtx*, or null to store the payload raw. `repr` is the brick's representation; it is written
// into the kind byte when it differs from the stream's (`layoutRepr`).
void writeSection(uint32_t brick, uint32_t version, SectionKind kind, Representation repr, Representation layoutRepr,
                  const std::vector<uint8_t>& raw, int zstdLevel, void* zstdContext, std::vector<uint8_t>& out);

struct SectionView {
  uint32_t brick = 0;
  uint32_t version = 0;
  SectionKind kind = SectionKind::Keyframe;
  Representation repr = Representation::L1;  // of the brick's payload (the stream's unless the kind byte says)
  uint8_t compression = 0;
  uint32_t rawSize = 0;
  const uint8_t* data = nullptr;
  uint32_t storedSize = 0;
};

// Parses one section header of the given format at data[0..size) and checks its CRC and sizes
// against the layout. On success *consumed is the section's full length.
CodecStatus parseSection(const StreamLayout& layout, uint8_t formatVersion, const uint8_t* data, size_t size,
                         SectionView* view, size_t* consumed);

// Parses every section of a frame whose header checked out (`frame` points at the header), in
// order, handing each to visit(const SectionView&) -> CodecStatus; stops at the first error, its
// own or the visitor's, and refuses bytes left after the last section.
template <typename Visit>
CodecStatus forEachSection(const StreamLayout& layout, const uint8_t* frame, const FrameHeader& header, Visit&& visit) {
  const uint8_t* p = frame + kFrameHeaderSize;
  size_t left = header.sectionBytes;
  for (uint32_t i = 0; i < header.sectionCount; ++i) {
    SectionView view;
    size_t consumed = 0;
    if (CodecStatus st = parseSection(layout, header.formatVersion, p, left, &view, &consumed); st != CodecStatus::Ok)
      return st;
    p += consumed;
    left -= consumed;
    if (CodecStatus st = visit(static_cast<const SectionView&>(view)); st != CodecStatus::Ok) return st;
  }
  return left == 0 ? CodecStatus::Ok : CodecStatus::TrailingBytes;
}

// Applies a decompressed payload of the given format to a brick's symbols. `active`/`symbols` hold
// the brick's state on entry (the base) and the new state on success.
CodecStatus applyPayload(uint8_t formatVersion, Representation repr, uint32_t probes, SectionKind kind,
                         const uint8_t* raw, size_t rawSize, uint8_t* active, ProbeSymbols* symbols);

}  // namespace probecast
