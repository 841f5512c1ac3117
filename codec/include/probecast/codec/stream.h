// Brick-based temporal coding of a probe grid and its container (docs/CODEC.md §5, §7).
//
// The grid (nx, ny, nz probes, probe (x, y, z) at index x + nx (y + ny z)) is split into bricks of
// brickDim³ probes (smaller at the far edges), brick (bx, by, bz) at index bx + nbx (by + nby bz).
// Each brick has versions: version 0 is "nothing held" (every probe inactive, all symbols 0).
// A new version is made when a frame changes a brick's quantised symbols by more than the
// dead-zone or changes which probes are active. Every version can be sent as
//   - a keyframe: the active mask and the records (record.h) of the active probes, or
//   - a delta from the previous version: active mask, changed mask, and per changed probe the
//     symbol differences (DC in the monotone code domain of rgb9e5.h, ratios in quantisation
//     steps), zig-zag coded, as Rice codes where those are shorter.
// Payloads are split into byte planes and zstd-compressed (stored raw when that is smaller).
// Inactive probes are never encoded. The encoder keeps exactly the state a decoder reaches, so
// decoding is bit-identical to the encoder's reconstruction after every frame.
//
// Wire format, little-endian. Frame = header (32 bytes) + sections:
//   header:  magic "PRBC" | u8 formatVersion (4; 1 to 3 are read) | u8 representation | u8 brickDim
//            | u8 flags (0) | u16 nx, ny, nz | u16 reserved (0) | u32 frameSequence | u32 sectionCount
//            | u32 sectionBytes | u32 CRC-32C of the preceding 28 bytes
//   section (format 3 and 4): varint brick | varint version | u8 kind (bits 0-1: 1 keyframe, 2 delta; bit 2:
//            the data is zstd-compressed; bit 3: 0; bits 4-7: the brick's representation when it is
//            not the stream's, else 0) | varint storedSize | u32 CRC-32C of the header bytes before it
//            and the data | data[storedSize]
//            Varints are unsigned LEB128 in their shortest form, at most 32 bits. Compressed data is
//            exactly one zstd frame without its 4-byte magic number, stating its content size (the
//            raw size); nothing may follow it.
//   payload: keyframe: active mask | byte planes of the active probes' records.
//            delta (format 3 and 4): u8 form | active mask, when form bit 0 (else the base's is kept)
//            | changed probes: u8 count and that many increasing u8 indices when form bit 1, else a
//            changed mask | the zig-zag differences of the changed probes' symbols, either
//              - byte planes: per wide symbol (DC codes; every one in fp16) a plane of the low bytes
//                and, unless form bit 2, a plane of the high bytes | per narrow symbol a plane; or
//              - Rice codes (format 4, form bit 3): a bit stream, low bit first in each byte, of the
//                wide parameter kw (4 bits) and the narrow one kn (3 bits), then per changed probe
//                its wide differences under kw and its narrow ones under kn (internal/rice_code.h:
//                quotient in unary and k low bits, or at a quotient of 8 eight ones
//                and the value in 16 or 8 bits), zero bits to the end of the last byte.
//            Each choice has one allowed spelling: the active mask only when it changed, the list
//            only for bricks of at most 256 probes when it is shorter than the mask (1 + count < mask
//            bytes), bit 2 exactly when the planes are used and every wide difference fits one
//            byte, Rice codes only when they are shorter than the planes, each parameter the
//            smallest of those that spell its differences in fewest bits, and a probe listed or
//            masked as changed only when one of its differences is not 0; form bits 4-7 are 0 (3
//            too in format 3). Anything else is refused (CodecStatus::NonCanonical). These rules are
//            about the payload: whether it is stored raw or compressed, and zstd's own choices, are
//            the encoder's; and so, in format 4, is byte planes where Rice codes are shorter (byte
//            planes of a large change compress; Rice codes do not).
// Format 1 and 2 sections: u32 brick | u32 version | u8 kind (bits 0-3: 1 keyframe, 2 delta; bits 4-7
//            as above) | u8 compression (0 raw, 1 zstd with magic) | u32 rawSize | u32 storedSize
//            | u32 CRC-32C of the preceding 18 bytes and the data | data; their deltas are active mask
//            | changed mask | both byte planes of every wide difference | narrow planes.
// A section is encoded once per brick version; frames for different subscribers reuse the same
// section bytes and differ only in their header.
// Format 2 differs from format 1 in what zh3h symbols mean: the parity of each probe's L1 ratio
// symbols chooses hallucinated ZH3 or plain L1 (record.h); and a brick of a zh3 or l2 stream may be
// sent in a cheaper representation (brickRepresentations, EncoderOptions::errorBound), said in its
// sections' kind byte. A version in another representation than the brick's last is a keyframe
// (a delta in another representation is refused). A format 1 frame still decodes, every zh3h probe
// hallucinating as before.
// Format 3 differs from format 2 only in how sections and deltas are spelled (the varint header,
// the delta's form byte); what they decode to is the same. A section header is 8 to 12 bytes instead
// of 22 (at most 16), and a small delta drops its masks and high bytes. Format 4 differs from format 3
// only in the Rice-coded differences (form bit 3): a few bits for each small difference where a byte
// plane spends a byte. Frames of formats 1 to 3 still decode; a carrier of bare sections (bus, wire)
// states the codec format and refuses another.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "probecast/codec/probe_volume.h"
#include "probecast/codec/record.h"
#include "probecast/codec/status.h"

namespace probecast {

constexpr uint8_t kFormatVersion = 4;         // what encoders write
constexpr uint8_t kOldestFormatVersion = 1;   // the oldest a decoder reads
constexpr uint8_t kCompactSectionFormat = 3;  // the first format with varint section headers and delta forms
constexpr uint8_t kRiceDeltaFormat = 4;       // the first format whose deltas may Rice-code their differences
constexpr size_t kFrameHeaderSize = 32;
constexpr size_t kFixedSectionHeaderSize = 22;  // formats 1 and 2
constexpr int kMaxGridDim = 1024;
constexpr int kMinBrickDim = 1;
constexpr int kMaxBrickDim = 8;
constexpr uint32_t kMaxBrickProbes = kMaxBrickDim * kMaxBrickDim * kMaxBrickDim;
constexpr uint32_t kMaxProbes = 1u << 24;

enum class SectionKind : uint8_t { Keyframe = 1, Delta = 2 };

struct StreamLayout {
  uint16_t grid[3] = {0, 0, 0};  // probes along x, y, z
  uint8_t brickDim = 4;          // probes per brick edge
  Representation repr = Representation::L1;
};

bool isValidLayout(const StreamLayout& layout);
// The stream layout of a probe grid; check it with isValidLayout (a grid may be too large).
StreamLayout streamLayoutFor(const ProbeGrid& grid, Representation repr, uint8_t brickDim);
// The probe grid a stream layout and its bounds describe.
ProbeGrid gridOf(const StreamLayout& layout, const GridBounds& bounds);
uint32_t probeCount(const StreamLayout& layout);
uint32_t brickCount(const StreamLayout& layout);
void brickGridSize(const StreamLayout& layout, uint32_t counts[3]);
// First probe coordinate and extent of a brick.
void brickProbeRange(const StreamLayout& layout, uint32_t brick, uint32_t begin[3], uint32_t size[3]);
uint32_t brickProbeCount(const StreamLayout& layout, uint32_t brick);
// Grid indices of the brick's probes in brick-local order (x fastest); `out` has brickProbeCount.
void brickProbeIndices(const StreamLayout& layout, uint32_t brick, uint32_t* out);

struct EncoderOptions {
  int deadzone = 0;    // changes of at most this many quantisation steps are not sent
  int zstdLevel = 3;
  bool compress = true;  // false: every section stored raw (byte-exact across zstd versions)
  // Noise rule: with per-probe noise (the standard error σ of the luminance of c00, see
  // ProbeVolume::noise) and a scale c > 0, a probe is not re-sent while what it would decode to
  // stays within c·σ of what the decoder holds, in the irradiance-weighted RMS over its
  // coefficients (each channel's differences divided by its share of the held c00's luminance).
  // Compared against the decoder's reconstruction, never against the last input, so skipped
  // changes cannot add up past the threshold. 0 = off.
  float noiseScale = 0.0f;
  // With the noise rule: a brick whose changes are all refinements (beyond c·σ but within 2c·σ of
  // what the decoder holds: the estimate converging, not new light) gets a new version only on an
  // update whose frame sequence is a multiple of this, so each brick's refinements go together and
  // every brick's in the same frame (one frame header, not one per brick). A change beyond 2c·σ, a
  // probe switching on or off, or one without noise goes at once. So does the change of a probe
  // whose light has held still for fewer updates than the interval (ProbeVolume::stillUpdates, given
  // to update): where light moves, a change within 2c·σ is the light moving on, not the estimate
  // converging. 0 = off.
  uint32_t refinementInterval = 0;
  // With the noise rule: a probe that would be re-sent (beyond c·σ of what the decoder holds) is kept
  // until it has been beyond for this many updates more in a row, so an estimate's one-update
  // excursion (a bright path) is not sent; one beyond 4c·σ is new light and goes at once. The
  // refinement interval then applies as before. 0 = off (re-sent on the first update beyond).
  uint32_t confirmations = 0;
  // Per-brick representation: > 0 sends each brick in the cheapest of brickRepresentations(repr)
  // whose relative irradiance error against the input, over the brick's active probes, stays within
  // this bound (exact over the sphere, RGB pooled: irradiance_error.h), the stream's own when none
  // does; a brick moves to a cheaper one only when it keeps within 0.8 of the bound, so noise does
  // not flip it. 0 = off.
  float errorBound = 0.0f;
};

// The representations a brick of a stream of `repr` may be sent in, cheapest first: l1, zh3 for a
// zh3 stream; l1, zh3, l2 for an l2 stream; `repr` alone for any other.
std::vector<Representation> brickRepresentations(Representation repr);

struct FrameHeader {
  uint8_t formatVersion = kFormatVersion;  // kOldestFormatVersion..kFormatVersion
  StreamLayout layout;
  uint32_t frameSequence = 0;
  uint32_t sectionCount = 0;
  uint32_t sectionBytes = 0;
};

// Parses and checks a frame header (magic, version, representation, layout, CRC, total size).
CodecStatus readFrameHeader(const uint8_t* data, size_t size, FrameHeader* header);
// Checks a whole frame's container without decoding it: the header, then every section's header
// fields, size and CRC, and that the sections fill the frame exactly. Cheap (two CRC passes over
// the bytes, no decompression), for relays and load tests that pass frames on unread. A frame
// that StreamDecoder::apply accepts always passes; one that passes may still fail to decode (a
// delta on a base the decoder lacks, a payload that is wrong under a correct CRC). `header` may be null.
CodecStatus verifyFrame(const uint8_t* data, size_t size, FrameHeader* header = nullptr);

struct SectionInfo {
  uint32_t brick = 0;
  uint32_t version = 0;
  SectionKind kind = SectionKind::Keyframe;
  size_t bytes = 0;  // the whole section: header and stored data
};

// Parses and checks the section at the start of data[0..size) (header fields against the layout,
// stored size within `size`, CRC-32C), for carriers that hold sections outside a frame. The section
// is read as kFormatVersion spells it; carriers state the codec format and refuse another. The
// payload itself is checked only when a decoder applies it.
CodecStatus readSection(const StreamLayout& layout, const uint8_t* data, size_t size, SectionInfo* info);

// A volume of the stream's grid over `bounds` from a coder's samples and mask (into `out`'s
// storage): decodedFrom is the layout's representation.
void copyStreamVolume(const StreamLayout& layout, const GridBounds& bounds, const float* probes, const uint8_t* active,
                      bool zh3PerPixel, ProbeVolume& out);

// Writes a frame: header plus the given sections (as produced by StreamEncoder) back to back.
void writeFrame(const StreamLayout& layout, uint32_t frameSequence, std::span<const std::span<const uint8_t>> sections,
                std::vector<uint8_t>& out);
// The same into storage the caller provides, of frameSize(sections) bytes (a transport's own
// buffer, so that the sections are copied once on their way out).
size_t frameSize(std::span<const std::span<const uint8_t>> sections);
void writeFrame(const StreamLayout& layout, uint32_t frameSequence, std::span<const std::span<const uint8_t>> sections,
                uint8_t* out);

class StreamEncoder {
 public:
  explicit StreamEncoder(const StreamLayout& layout, const EncoderOptions& options = {});
  ~StreamEncoder();
  StreamEncoder(const StreamEncoder&) = delete;
  StreamEncoder& operator=(const StreamEncoder&) = delete;

  // Ingests a frame: probeCount(layout) probes of 27 floats (sh.h layout) and one state byte each
  // (nonzero = active; null = all active), and optionally one noise value per probe (null: none;
  // negative or non-finite values count as 0) and how many updates each probe's light has held
  // still (ProbeVolume::stillUpdates; null: unknown, every probe as if still for long). Returns the
  // number of bricks given a new version.
  uint32_t update(const float* probes, const uint8_t* active, const float* noise = nullptr,
                  const uint32_t* stillUpdates = nullptr);

  // With the noise rule: how much the viewers see of each probe, probeCount(layout) weights ≥ 0 (a
  // probe's share of the views' pixels, or 1 in some view and 0 in none); empty: every probe alike.
  // A probe of weight w is held within c·σ·(w / w̄)^(−1/3), w̄ the mean weight of the probes with
  // one, within [kViewScaleMin, kViewScaleMax] × c·σ: the spacing of re-sends that spends bytes where
  // the views show the held probes' lag (a lag that grows to t costs about w·t²/3 of the views'
  // squared error and is re-sent about 1/t as often; the sum is least for t ∝ w^(−1/3)). A probe
  // nobody sees (w = 0) takes the most. The other noise thresholds (2c·σ, 4c·σ) scale alike. Returns
  // false and keeps the weights it had when the count is wrong or a weight is negative or not finite,
  // or when no weight is positive.
  bool setViewWeights(std::span<const float> weights);
  static constexpr float kViewScaleMin = 0.5f;
  static constexpr float kViewScaleMax = 4.0f;

  const StreamLayout& layout() const;
  uint32_t frameSequence() const;  // number of update() calls so far
  uint32_t brickVersion(uint32_t brick) const;
  // Relative change of the brick's reconstruction made by its latest version (sum |Δc| / sum |c|).
  float brickChange(uint32_t brick) const;
  // Relative change between a holder's version and the current one, for priority: the sum of
  // brickChange() of the versions after `heldVersion` (remembered for the last 16 versions),
  // 1 when the holder has nothing or is further behind, 0 when current.
  float changeSince(uint32_t brick, uint32_t heldVersion) const;
  // The section taking a holder of version-1 to the current version; empty at version 0. A keyframe
  // when that version changed the brick's representation (deltaIsKeyframe).
  std::span<const uint8_t> deltaSection(uint32_t brick) const;
  bool deltaIsKeyframe(uint32_t brick) const;
  // The representation the brick's current version is in (the stream's without an error bound).
  Representation brickRepresentation(uint32_t brick) const;
  // A keyframe section of the current version (encoded on first request, then cached).
  std::span<const uint8_t> keyframeSection(uint32_t brick);
  // What a holder of `heldVersion` needs: empty if current, the delta if one version behind,
  // a keyframe otherwise.
  std::span<const uint8_t> sectionFor(uint32_t brick, uint32_t heldVersion);
  // Convenience: a frame with every brick's latest delta that changed in the last update()
  // (what a subscriber that holds everything needs).
  void writeChangedFrame(std::vector<uint8_t>& out) const;
  // A frame of keyframes of every brick (what a new subscriber needs).
  void writeKeyframeFrame(std::vector<uint8_t>& out);

  // The decoder's reconstruction: 27 floats per probe (0 for inactive probes), and active flags.
  const float* reconstruction() const;
  const uint8_t* activeMask() const;
  // The reconstruction as a volume over `bounds`, into `out` (its storage reused).
  void copyVolume(const GridBounds& bounds, ProbeVolume& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class StreamDecoder {
 public:
  explicit StreamDecoder(const StreamLayout& layout);
  ~StreamDecoder();
  StreamDecoder(const StreamDecoder&) = delete;
  StreamDecoder& operator=(const StreamDecoder&) = delete;

  // Applies one frame. All or nothing: on any error the decoder's state is unchanged.
  CodecStatus apply(const uint8_t* data, size_t size);

  const StreamLayout& layout() const;
  uint32_t brickVersion(uint32_t brick) const;
  uint32_t lastFrameSequence() const;
  const float* probes() const;      // 27 floats per probe, 0 for inactive probes
  const uint8_t* activeMask() const;  // 1 = active
  // What it holds as a volume over `bounds`, into `out` (its storage reused); zh3PerPixel as set.
  void copyVolume(const GridBounds& bounds, ProbeVolume& out) const;
  // zh3h only: true decodes L1 with a zero L2 band, for a renderer that hallucinates ZH3 per
  // pixel (ProbeVolume::zh3PerPixel); false (the default) hallucinates per probe. Set it before
  // the first frame: probes decoded earlier stay as they were decoded.
  void setZh3PerPixel(bool zh3PerPixel);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast
