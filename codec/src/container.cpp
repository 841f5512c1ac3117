// Grid/brick layout, frame header, and the section format (docs/CODEC.md §7).
#include <algorithm>
#include <cassert>
#include <cstring>

#include <zstd.h>

#include "brick_section.h"
#include "byte_io.h"
#include "probecast/codec/crc32c.h"
#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/stream.h"

namespace probecast {
namespace {

constexpr uint8_t kMagic[4] = {'P', 'R', 'B', 'C'};

uint32_t ceilDiv(uint32_t a, uint32_t b) { return (a + b - 1) / b; }

}  // namespace

const char* codecStatusName(CodecStatus status) {
  switch (status) {
    case CodecStatus::Ok: return "ok";
    case CodecStatus::Truncated: return "truncated";
    case CodecStatus::BadMagic: return "bad magic";
    case CodecStatus::UnsupportedVersion: return "unsupported format version";
    case CodecStatus::BadRepresentation: return "bad representation";
    case CodecStatus::BadLayout: return "bad grid layout";
    case CodecStatus::LayoutMismatch: return "layout mismatch";
    case CodecStatus::HeaderChecksum: return "header checksum mismatch";
    case CodecStatus::SectionChecksum: return "section checksum mismatch";
    case CodecStatus::BadBrickIndex: return "brick index out of range";
    case CodecStatus::DuplicateBrick: return "duplicate brick in frame";
    case CodecStatus::BadSectionKind: return "bad section kind or compression";
    case CodecStatus::SectionTooLarge: return "section too large";
    case CodecStatus::DecompressFailed: return "decompression failed";
    case CodecStatus::SizeMismatch: return "size mismatch";
    case CodecStatus::BaseVersionMismatch: return "delta base version not held";
    case CodecStatus::BadVersion: return "version goes backwards";
    case CodecStatus::BadMask: return "bad probe mask";
    case CodecStatus::BadSymbol: return "symbol out of range";
    case CodecStatus::TrailingBytes: return "trailing bytes";
    case CodecStatus::NonCanonical: return "non-canonical encoding";
  }
  return "unknown status";
}

bool isValidLayout(const StreamLayout& layout) {
  uint64_t total = 1;
  for (uint16_t n : layout.grid) {
    if (n < 1 || n > kMaxGridDim) return false;
    total *= n;
  }
  return total <= kMaxProbes && layout.brickDim >= kMinBrickDim && layout.brickDim <= kMaxBrickDim &&
         isValidRepresentation(static_cast<uint8_t>(layout.repr));
}

StreamLayout streamLayoutFor(const ProbeGrid& grid, Representation repr, uint8_t brickDim) {
  StreamLayout layout;
  for (int a = 0; a < 3; ++a)  // too many probes along an axis: 0, which isValidLayout refuses
    layout.grid[a] = grid.dims[a] <= static_cast<uint32_t>(kMaxGridDim) ? static_cast<uint16_t>(grid.dims[a]) : 0;
  layout.brickDim = brickDim;
  layout.repr = repr;
  return layout;
}

void copyStreamVolume(const StreamLayout& layout, const GridBounds& bounds, const float* probes, const uint8_t* active,
                      bool zh3PerPixel, ProbeVolume& out) {
  const size_t n = probeCount(layout);
  out.grid = gridOf(layout, bounds);
  out.probes.assign(probes, probes + n * kProbeFloats);
  out.active.assign(active, active + n);
  out.decodedFrom = layout.repr;
  out.zh3PerPixel = zh3PerPixel;
}

ProbeGrid gridOf(const StreamLayout& layout, const GridBounds& bounds) {
  ProbeGrid grid;
  for (int a = 0; a < 3; ++a) grid.dims[a] = layout.grid[a];
  grid.bounds = bounds;
  return grid;
}

uint32_t probeCount(const StreamLayout& layout) {
  return static_cast<uint32_t>(layout.grid[0]) * layout.grid[1] * layout.grid[2];
}

void brickGridSize(const StreamLayout& layout, uint32_t counts[3]) {
  for (int a = 0; a < 3; ++a) counts[a] = ceilDiv(layout.grid[a], layout.brickDim);
}

uint32_t brickCount(const StreamLayout& layout) {
  uint32_t n[3];
  brickGridSize(layout, n);
  return n[0] * n[1] * n[2];
}

void brickProbeRange(const StreamLayout& layout, uint32_t brick, uint32_t begin[3], uint32_t size[3]) {
  uint32_t n[3];
  brickGridSize(layout, n);
  assert(brick < n[0] * n[1] * n[2]);
  const uint32_t coord[3] = {brick % n[0], (brick / n[0]) % n[1], brick / (n[0] * n[1])};
  for (int a = 0; a < 3; ++a) {
    begin[a] = coord[a] * layout.brickDim;
    size[a] = std::min<uint32_t>(layout.brickDim, layout.grid[a] - begin[a]);
  }
}

uint32_t brickProbeCount(const StreamLayout& layout, uint32_t brick) {
  uint32_t begin[3], size[3];
  brickProbeRange(layout, brick, begin, size);
  return size[0] * size[1] * size[2];
}

void brickProbeIndices(const StreamLayout& layout, uint32_t brick, uint32_t* out) {
  uint32_t begin[3], size[3];
  brickProbeRange(layout, brick, begin, size);
  uint32_t k = 0;
  for (uint32_t z = 0; z < size[2]; ++z)
    for (uint32_t y = 0; y < size[1]; ++y)
      for (uint32_t x = 0; x < size[0]; ++x)
        out[k++] = (begin[0] + x) + layout.grid[0] * ((begin[1] + y) + layout.grid[1] * (begin[2] + z));
}

size_t frameSize(std::span<const std::span<const uint8_t>> sections) {
  size_t size = kFrameHeaderSize;
  for (const auto& s : sections) size += s.size();
  return size;
}

void writeFrame(const StreamLayout& layout, uint32_t frameSequence, std::span<const std::span<const uint8_t>> sections,
                uint8_t* out) {
  assert(isValidLayout(layout));
  const size_t sectionBytes = frameSize(sections) - kFrameHeaderSize;
  uint8_t* p = out;
  const auto put16 = [&p](uint16_t v) {
    p[0] = static_cast<uint8_t>(v);
    p[1] = static_cast<uint8_t>(v >> 8);
    p += 2;
  };
  const auto put32 = [&p](uint32_t v) {
    setU32(p, v);
    p += 4;
  };
  std::memcpy(p, kMagic, 4);
  p += 4;
  *p++ = kFormatVersion;
  *p++ = static_cast<uint8_t>(layout.repr);
  *p++ = layout.brickDim;
  *p++ = 0;  // flags
  for (uint16_t n : layout.grid) put16(n);
  put16(0);  // reserved
  put32(frameSequence);
  put32(static_cast<uint32_t>(sections.size()));
  put32(static_cast<uint32_t>(sectionBytes));
  put32(crc32c(out, 28));
  for (const auto& s : sections) {
    if (!s.empty()) std::memcpy(p, s.data(), s.size());
    p += s.size();
  }
}

void writeFrame(const StreamLayout& layout, uint32_t frameSequence, std::span<const std::span<const uint8_t>> sections,
                std::vector<uint8_t>& out) {
  out.resize(frameSize(sections));
  writeFrame(layout, frameSequence, sections, out.data());
}

CodecStatus readFrameHeader(const uint8_t* data, size_t size, FrameHeader* header) {
  if (size < kFrameHeaderSize) return CodecStatus::Truncated;
  if (std::memcmp(data, kMagic, 4) != 0) return CodecStatus::BadMagic;
  if (data[4] < kOldestFormatVersion || data[4] > kFormatVersion) return CodecStatus::UnsupportedVersion;
  if (crc32c(data, 28) != getU32(data + 28)) return CodecStatus::HeaderChecksum;
  if (!isValidRepresentation(data[5])) return CodecStatus::BadRepresentation;
  FrameHeader h;
  h.formatVersion = data[4];
  h.layout.repr = static_cast<Representation>(data[5]);
  h.layout.brickDim = data[6];
  for (int a = 0; a < 3; ++a) h.layout.grid[a] = getU16(data + 8 + 2 * a);
  if (data[7] != 0 || getU16(data + 14) != 0 || !isValidLayout(h.layout)) return CodecStatus::BadLayout;
  h.frameSequence = getU32(data + 16);
  h.sectionCount = getU32(data + 20);
  h.sectionBytes = getU32(data + 24);
  if (h.sectionCount > brickCount(h.layout)) return CodecStatus::BadBrickIndex;
  if (size - kFrameHeaderSize < h.sectionBytes) return CodecStatus::Truncated;
  if (size - kFrameHeaderSize > h.sectionBytes) return CodecStatus::TrailingBytes;
  *header = h;
  return CodecStatus::Ok;
}

CodecStatus verifyFrame(const uint8_t* data, size_t size, FrameHeader* header) {
  FrameHeader h;
  if (CodecStatus st = readFrameHeader(data, size, &h); st != CodecStatus::Ok) return st;
  if (CodecStatus st = forEachSection(h.layout, data, h, [](const SectionView&) { return CodecStatus::Ok; });
      st != CodecStatus::Ok)
    return st;
  if (header) *header = h;
  return CodecStatus::Ok;
}

void BrickTable::build(const StreamLayout& layout) {
  const uint32_t bricks = brickCount(layout);
  first.resize(bricks + 1);
  probes.resize(probeCount(layout));
  uint32_t at = 0;
  for (uint32_t b = 0; b < bricks; ++b) {
    first[b] = at;
    brickProbeIndices(layout, b, probes.data() + at);
    at += brickProbeCount(layout, b);
  }
  first[bricks] = at;
}

bool locateSection(const uint8_t* section, size_t size, SectionBytes* out) {
  SectionBytes b;
  uint32_t value = 0;
  size_t at = 0;
  for (int field = 0; field < 3; ++field) {  // brick, version, (kind byte), stored size
    const size_t n = getVarint(section + at, size - at, &value);
    if (n == 0) return false;
    at += n;
    if (field == 1) {
      if (at >= size) return false;
      b.kindAt = at++;
    }
  }
  b.storedSize = value;
  b.crcAt = at;
  b.dataAt = at + 4;
  if (b.dataAt > size || value > size - b.dataAt) return false;
  *out = b;
  return true;
}

std::vector<uint8_t> sealSection(uint32_t brick, uint32_t version, uint8_t kindByte, std::span<const uint8_t> data) {
  std::vector<uint8_t> out;
  putVarint(out, brick);
  putVarint(out, version);
  out.push_back(kindByte);
  putVarint(out, static_cast<uint32_t>(data.size()));
  const size_t crcAt = out.size();
  putU32(out, 0);
  out.insert(out.end(), data.begin(), data.end());
  setU32(out.data() + crcAt, crc32c(data.data(), data.size(), crc32c(out.data(), crcAt)));
  return out;
}

void rewriteFrameChecksums(std::vector<uint8_t>& f) {
  if (f.size() < kFrameHeaderSize) return;
  setU32(f.data() + 28, crc32c(f.data(), 28));
  const bool compact = f[4] >= kCompactSectionFormat;
  size_t at = kFrameHeaderSize;
  while (at < f.size()) {
    SectionBytes b;
    if (compact) {
      if (!locateSection(f.data() + at, f.size() - at, &b)) return;
    } else {
      if (f.size() - at < kFixedSectionHeaderSize) return;
      b.crcAt = 18;
      b.dataAt = kFixedSectionHeaderSize;
      b.storedSize = getU32(f.data() + at + 14);
      if (b.storedSize > f.size() - at - b.dataAt) return;
    }
    const uint32_t crc = crc32c(f.data() + at + b.dataAt, b.storedSize, crc32c(f.data() + at, b.crcAt));
    setU32(f.data() + at + b.crcAt, crc);
    at += b.dataAt + b.storedSize;
  }
}

size_t maxRawSectionSize(const StreamLayout& layout, uint32_t brick) {
  const uint32_t probes = brickProbeCount(layout, brick);
  const SymbolShape shape = symbolShape(layout.repr);
  const size_t perProbe = std::max<size_t>(recordSize(layout.repr), 2u * shape.wide + shape.narrow);
  return 1u + 2u * maskBytes(probes) + probes * perProbe;  // a format 3 delta's form byte, both masks
}

std::vector<Representation> brickRepresentations(Representation repr) {
  switch (repr) {
    case Representation::Zh3: return {Representation::L1, Representation::Zh3};
    case Representation::L2: return {Representation::L1, Representation::Zh3, Representation::L2};
    default: return {repr};
  }
}

void writeSection(uint32_t brick, uint32_t version, SectionKind kind, Representation repr, Representation layoutRepr,
                  const std::vector<uint8_t>& raw, int zstdLevel, void* zstdContext, std::vector<uint8_t>& out) {
  // The payload goes first, behind room for the longest header and its CRC, since the header holds
  // its size; it then moves down to right after the actual header (never up).
  constexpr size_t kRoom = 20;  // three varints of at most 5 bytes, the kind byte, the CRC
  out.clear();
  size_t stored = raw.size();
  bool zstd = false;
  if (!raw.empty() && zstdContext != nullptr) {
    // A plain zstd frame (with its content size) written 4 bytes early, so its magic falls before
    // kRoom and is dropped.
    const size_t bound = ZSTD_compressBound(raw.size());
    out.resize(kRoom + bound);
    const size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstdContext), out.data() + kRoom - 4, bound + 4,
                                       raw.data(), raw.size(), zstdLevel);
    if (!ZSTD_isError(n) && n > 4 && std::memcmp(out.data() + kRoom - 4, kZstdMagic, 4) == 0 && n - 4 < raw.size()) {
      stored = n - 4;
      zstd = true;
    }
  }
  if (!zstd) {
    out.resize(kRoom + raw.size());
    if (!raw.empty()) std::memcpy(out.data() + kRoom, raw.data(), raw.size());
  }
  out.resize(kRoom + stored);
  std::vector<uint8_t> header;
  header.reserve(kRoom - 4);
  putVarint(header, brick);
  putVarint(header, version);
  const uint8_t reprBits = repr == layoutRepr ? 0 : static_cast<uint8_t>(static_cast<uint8_t>(repr) << 4);
  header.push_back(static_cast<uint8_t>(static_cast<uint8_t>(kind) | (zstd ? kSectionZstdBit : 0) | reprBits));
  putVarint(header, static_cast<uint32_t>(stored));
  // Header, then its CRC (of the header and the data), then the data.
  std::memmove(out.data() + header.size() + 4, out.data() + kRoom, stored);
  out.resize(header.size() + 4 + stored);
  std::memcpy(out.data(), header.data(), header.size());
  uint32_t crc = crc32c(header.data(), header.size());
  crc = crc32c(out.data() + header.size() + 4, stored, crc);
  setU32(out.data() + header.size(), crc);
}

std::span<const uint8_t> zstdFrameOf(uint8_t formatVersion, const uint8_t* data, size_t size,
                                     std::vector<uint8_t>& scratch) {
  if (formatVersion < kCompactSectionFormat) return {data, size};
  scratch.assign(kZstdMagic, kZstdMagic + 4);
  scratch.insert(scratch.end(), data, data + size);
  return scratch;
}

namespace {

// Format 1 and 2 sections: a fixed 22-byte header.
CodecStatus parseFixedSection(const uint8_t* data, size_t size, SectionView& v, uint8_t& kindByte, size_t& headerSize) {
  if (size < kFixedSectionHeaderSize) return CodecStatus::Truncated;
  v.brick = getU32(data);
  v.version = getU32(data + 4);
  kindByte = data[8];
  v.compression = data[9];
  v.rawSize = getU32(data + 10);
  v.storedSize = getU32(data + 14);
  if (size - kFixedSectionHeaderSize < v.storedSize) return CodecStatus::Truncated;
  uint32_t crc = crc32c(data, 18);
  crc = crc32c(data + kFixedSectionHeaderSize, v.storedSize, crc);
  if (crc != getU32(data + 18)) return CodecStatus::SectionChecksum;
  if (v.compression != kCompressionRaw && v.compression != kCompressionZstd) return CodecStatus::BadSectionKind;
  headerSize = kFixedSectionHeaderSize;
  return CodecStatus::Ok;
}

// Format 3 sections: varint brick, version and stored size around the kind byte, then the CRC.
CodecStatus parseCompactSection(const uint8_t* data, size_t size, SectionView& v, uint8_t& kindByte,
                                size_t& headerSize) {
  size_t at = 0;
  const auto varint = [&](uint32_t* value) {
    const size_t n = getVarint(data + at, size - at, value);
    if (n == 0) {  // cut off, or not in its shortest form
      size_t run = at;
      while (run < size && run < at + 5 && (data[run] & 0x80)) ++run;
      return run == size ? CodecStatus::Truncated : CodecStatus::NonCanonical;
    }
    at += n;
    return CodecStatus::Ok;
  };
  if (CodecStatus st = varint(&v.brick); st != CodecStatus::Ok) return st;
  if (CodecStatus st = varint(&v.version); st != CodecStatus::Ok) return st;
  if (at >= size) return CodecStatus::Truncated;
  kindByte = data[at++];
  if (CodecStatus st = varint(&v.storedSize); st != CodecStatus::Ok) return st;
  if (size - at < 4 || size - at - 4 < v.storedSize) return CodecStatus::Truncated;
  uint32_t crc = crc32c(data, at);
  crc = crc32c(data + at + 4, v.storedSize, crc);
  if (crc != getU32(data + at)) return CodecStatus::SectionChecksum;
  headerSize = at + 4;
  v.compression = (kindByte & kSectionZstdBit) ? kCompressionZstd : kCompressionRaw;
  if (kindByte & 0x08) return CodecStatus::BadSectionKind;
  kindByte = static_cast<uint8_t>(kindByte & 0xf3);
  v.rawSize = v.storedSize;  // raw data; compressed, the zstd frame's content size (parseSection)
  return CodecStatus::Ok;
}

}  // namespace

CodecStatus parseSection(const StreamLayout& layout, uint8_t formatVersion, const uint8_t* data, size_t size,
                         SectionView* view, size_t* consumed) {
  SectionView v;
  uint8_t kindByte = 0;
  size_t headerSize = 0;
  const CodecStatus parsed = formatVersion >= kCompactSectionFormat
                                 ? parseCompactSection(data, size, v, kindByte, headerSize)
                                 : parseFixedSection(data, size, v, kindByte, headerSize);
  if (parsed != CodecStatus::Ok) return parsed;
  if (v.compression == kCompressionZstd) {
    // Exactly one zstd frame (a second one, even empty, would be another spelling of the payload)
    // that states its content size: format 3's raw size, the stated one's twin in formats 1 and 2.
    thread_local std::vector<uint8_t> scratch;
    const std::span<const uint8_t> frame = zstdFrameOf(formatVersion, data + headerSize, v.storedSize, scratch);
    const size_t whole = ZSTD_findFrameCompressedSize(frame.data(), frame.size());
    const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
    // ZSTD_CONTENTSIZE_UNKNOWN and _ERROR are both above any 32-bit size.
    if (ZSTD_isError(whole) || whole != frame.size() || content > 0xffffffffu) return CodecStatus::DecompressFailed;
    if (formatVersion >= kCompactSectionFormat) v.rawSize = static_cast<uint32_t>(content);
    else if (content != v.rawSize) return CodecStatus::DecompressFailed;
  }
  if (v.brick >= brickCount(layout)) return CodecStatus::BadBrickIndex;
  const uint8_t kind = kindByte & 0x0f, reprCode = kindByte >> 4;
  if (kind != static_cast<uint8_t>(SectionKind::Keyframe) && kind != static_cast<uint8_t>(SectionKind::Delta))
    return CodecStatus::BadSectionKind;
  v.kind = static_cast<SectionKind>(kind);
  v.repr = layout.repr;
  if (reprCode != 0) {  // one of the stream's cheaper brick representations, never its own spelled out
    const std::vector<Representation> allowed = brickRepresentations(layout.repr);
    if (reprCode == static_cast<uint8_t>(layout.repr) ||
        std::find(allowed.begin(), allowed.end(), static_cast<Representation>(reprCode)) == allowed.end())
      return CodecStatus::BadSectionKind;
    v.repr = static_cast<Representation>(reprCode);
  }
  if (v.rawSize > maxRawSectionSize(layout, v.brick)) return CodecStatus::SectionTooLarge;
  if (v.compression == kCompressionRaw && v.storedSize != v.rawSize) return CodecStatus::SizeMismatch;
  v.data = data + headerSize;
  *view = v;
  *consumed = headerSize + v.storedSize;
  return CodecStatus::Ok;
}

CodecStatus readSection(const StreamLayout& layout, const uint8_t* data, size_t size, SectionInfo* info) {
  SectionView view;
  size_t consumed = 0;
  if (CodecStatus st = parseSection(layout, kFormatVersion, data, size, &view, &consumed); st != CodecStatus::Ok)
    return st;
  info->brick = view.brick;
  info->version = view.version;
  info->kind = view.kind;
  info->bytes = consumed;
  return CodecStatus::Ok;
}

}  // namespace probecast
