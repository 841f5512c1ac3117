// Keyframe and delta payloads of one brick: masks, byte planes, zig-zag symbol differences.
#include <algorithm>
#include <cstring>

#include "brick_section.h"
#include "byte_io.h"

namespace probecast {
namespace {

void appendMask(uint32_t probes, const uint8_t* flags, std::vector<uint8_t>& out) {
  const size_t at = out.size();
  out.resize(at + maskBytes(probes), 0);
  for (uint32_t i = 0; i < probes; ++i)
    if (flags[i]) setMaskBit(out.data() + at, i);
}

// Bits past the last probe must be zero, so every brick state has exactly one encoding.
bool maskTailIsClear(const uint8_t* mask, uint32_t probes) {
  const uint32_t bytes = maskBytes(probes);
  const uint32_t used = probes - 8 * (bytes - 1);
  return used == 8 || (mask[bytes - 1] >> used) == 0;
}

uint32_t popcount(const uint8_t* mask, uint32_t bytes) {
  uint32_t n = 0;
  for (uint32_t i = 0; i < bytes; ++i) n += static_cast<uint32_t>(__builtin_popcount(mask[i]));
  return n;
}

}  // namespace

void buildKeyframePayload(Representation repr, uint32_t probes, const uint8_t* active, const ProbeSymbols* symbols,
                          std::vector<uint8_t>& out) {
  out.clear();
  appendMask(probes, active, out);
  const size_t record = recordSize(repr);
  uint32_t count = 0;
  for (uint32_t i = 0; i < probes; ++i) count += active[i] ? 1 : 0;
  const size_t base = out.size();
  out.resize(base + count * record);
  uint8_t bytes[kMaxRecordBytes];
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    if (!active[i]) continue;
    symbolsToRecord(repr, symbols[i], bytes);
    for (size_t b = 0; b < record; ++b) out[base + b * count + k] = bytes[b];  // byte plane b
    ++k;
  }
}

void buildDeltaPayload(Representation repr, uint32_t probes, const uint8_t* baseActive, const uint8_t* active,
                       const ProbeSymbols* base, const ProbeSymbols* next, std::vector<uint8_t>& out) {
  const SymbolShape shape = symbolShape(repr);
  const uint32_t mbytes = maskBytes(probes);
  uint32_t changed = 0;
  bool sameActive = true, narrowWide = true;
  for (uint32_t i = 0; i < probes; ++i) {
    sameActive = sameActive && (baseActive[i] != 0) == (active[i] != 0);
    if (!active[i] || std::memcmp(&base[i], &next[i], sizeof(ProbeSymbols)) == 0) continue;
    ++changed;
    for (int w = 0; w < shape.wide; ++w)
      narrowWide = narrowWide && zigzag16(static_cast<uint16_t>(next[i].wide[w] - base[i].wide[w])) < 256;
  }
  const bool list = probes <= 256 && 1 + changed < mbytes;
  out.clear();
  out.push_back(static_cast<uint8_t>((sameActive ? 0 : kDeltaActiveMask) | (list ? kDeltaChangedList : 0) |
                                     (narrowWide ? kDeltaNarrowWide : 0)));
  if (!sameActive) appendMask(probes, active, out);
  const auto isChanged = [&](uint32_t i) {
    return active[i] && std::memcmp(&base[i], &next[i], sizeof(ProbeSymbols)) != 0;
  };
  if (list) {
    out.push_back(static_cast<uint8_t>(changed));
    for (uint32_t i = 0; i < probes; ++i)
      if (isChanged(i)) out.push_back(static_cast<uint8_t>(i));
  } else {
    const size_t at = out.size();
    out.resize(at + mbytes, 0);
    for (uint32_t i = 0; i < probes; ++i)
      if (isChanged(i)) setMaskBit(out.data() + at, i);
  }
  // Planes: each wide difference's low byte (and high byte unless all fit one), then the narrow ones.
  const uint32_t wideBytes = narrowWide ? 1 : 2;
  const size_t planes = out.size();
  out.resize(planes + changed * (wideBytes * shape.wide + shape.narrow));
  uint8_t* p = out.data() + planes;
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    if (!isChanged(i)) continue;
    for (int w = 0; w < shape.wide; ++w) {
      const uint16_t z = zigzag16(static_cast<uint16_t>(next[i].wide[w] - base[i].wide[w]));
      p[(wideBytes * w) * changed + k] = static_cast<uint8_t>(z & 0xff);
      if (wideBytes == 2) p[(2 * w + 1) * changed + k] = static_cast<uint8_t>(z >> 8);
    }
    for (int j = 0; j < shape.narrow; ++j)
      p[(wideBytes * shape.wide + j) * changed + k] =
          zigzag8(static_cast<uint8_t>(next[i].narrow[j] - base[i].narrow[j]));
    ++k;
  }
}

namespace {

// A delta's masks and where its planes start, whatever the format spelled them as.
struct DeltaForm {
  uint8_t activeMask[kMaxBrickProbes / 8] = {};
  uint8_t changedMask[kMaxBrickProbes / 8] = {};
  uint32_t changed = 0;
  uint32_t wideBytes = 2;
  const uint8_t* planes = nullptr;
  size_t planeBytes = 0;
};

// Formats 1 and 2: active mask, changed mask, two bytes per wide difference.
CodecStatus readFixedDelta(uint32_t probes, const uint8_t* raw, size_t rawSize, DeltaForm& d) {
  const uint32_t mbytes = maskBytes(probes);
  if (rawSize < 2u * mbytes) return CodecStatus::SizeMismatch;
  std::memcpy(d.activeMask, raw, mbytes);
  std::memcpy(d.changedMask, raw + mbytes, mbytes);
  if (!maskTailIsClear(d.changedMask, probes)) return CodecStatus::BadMask;
  d.changed = popcount(d.changedMask, mbytes);
  d.planes = raw + 2u * mbytes;
  d.planeBytes = rawSize - 2u * mbytes;
  return CodecStatus::Ok;
}

// Format 3: the form byte says which of the active mask, the changed set and the wide differences'
// high bytes are spelled out; each has one allowed spelling (the shorter), so a state has one encoding.
CodecStatus readCompactDelta(uint32_t probes, const uint8_t* baseActive, const uint8_t* raw, size_t rawSize,
                             DeltaForm& d) {
  const uint32_t mbytes = maskBytes(probes);
  if (rawSize < 1) return CodecStatus::SizeMismatch;
  const uint8_t form = raw[0];
  if (form & ~(kDeltaActiveMask | kDeltaChangedList | kDeltaNarrowWide)) return CodecStatus::NonCanonical;
  size_t at = 1;
  if (form & kDeltaActiveMask) {
    if (rawSize - at < mbytes) return CodecStatus::SizeMismatch;
    std::memcpy(d.activeMask, raw + at, mbytes);
    at += mbytes;
    bool same = true;
    for (uint32_t i = 0; i < probes; ++i) same = same && maskBit(d.activeMask, i) == (baseActive[i] != 0);
    if (same && maskTailIsClear(d.activeMask, probes)) return CodecStatus::NonCanonical;  // the base's, spelled out
  } else {
    for (uint32_t i = 0; i < probes; ++i)
      if (baseActive[i]) setMaskBit(d.activeMask, i);
  }
  if (form & kDeltaChangedList) {
    if (rawSize - at < 1) return CodecStatus::SizeMismatch;
    d.changed = raw[at++];
    if (rawSize - at < d.changed) return CodecStatus::SizeMismatch;
    for (uint32_t k = 0; k < d.changed; ++k) {
      const uint32_t i = raw[at + k];
      if (i >= probes || (k > 0 && i <= raw[at + k - 1])) return CodecStatus::BadMask;  // outside, or not increasing
      setMaskBit(d.changedMask, i);
    }
    at += d.changed;
  } else {
    if (rawSize - at < mbytes) return CodecStatus::SizeMismatch;
    std::memcpy(d.changedMask, raw + at, mbytes);
    at += mbytes;
    if (!maskTailIsClear(d.changedMask, probes)) return CodecStatus::BadMask;
    d.changed = popcount(d.changedMask, mbytes);
  }
  if (((form & kDeltaChangedList) != 0) != (probes <= 256 && 1 + d.changed < mbytes)) return CodecStatus::NonCanonical;
  d.wideBytes = (form & kDeltaNarrowWide) ? 1 : 2;
  d.planes = raw + at;
  d.planeBytes = rawSize - at;
  return CodecStatus::Ok;
}

}  // namespace

CodecStatus applyPayload(uint8_t formatVersion, Representation repr, uint32_t probes, SectionKind kind,
                         const uint8_t* raw, size_t rawSize, uint8_t* active, ProbeSymbols* symbols) {
  const uint32_t mbytes = maskBytes(probes);
  if (kind == SectionKind::Keyframe) {
    if (rawSize < mbytes) return CodecStatus::SizeMismatch;
    const uint8_t* activeMask = raw;
    if (!maskTailIsClear(activeMask, probes)) return CodecStatus::BadMask;
    const uint32_t count = popcount(activeMask, mbytes);
    const size_t record = recordSize(repr);
    if (rawSize != mbytes + count * record) return CodecStatus::SizeMismatch;
    const uint8_t* planes = raw + mbytes;
    uint8_t bytes[kMaxRecordBytes];
    uint32_t k = 0;
    for (uint32_t i = 0; i < probes; ++i) {
      active[i] = maskBit(activeMask, i) ? 1 : 0;
      if (!active[i]) {
        symbols[i] = ProbeSymbols{};
        continue;
      }
      for (size_t b = 0; b < record; ++b) bytes[b] = planes[b * count + k];
      recordToSymbols(repr, bytes, &symbols[i]);
      ++k;
    }
    return CodecStatus::Ok;
  }

  DeltaForm d;
  const CodecStatus form = formatVersion >= kCompactSectionFormat ? readCompactDelta(probes, active, raw, rawSize, d)
                                                                   : readFixedDelta(probes, raw, rawSize, d);
  if (form != CodecStatus::Ok) return form;
  if (!maskTailIsClear(d.activeMask, probes)) return CodecStatus::BadMask;
  for (uint32_t b = 0; b < mbytes; ++b)
    if (d.changedMask[b] & ~d.activeMask[b]) return CodecStatus::BadMask;
  const SymbolShape shape = symbolShape(repr);
  const uint32_t changed = d.changed;
  if (d.planeBytes != changed * (d.wideBytes * shape.wide + shape.narrow)) return CodecStatus::SizeMismatch;
  const uint8_t* p = d.planes;
  if (d.wideBytes == 2 && formatVersion >= kCompactSectionFormat) {  // high bytes spelled out: one must be needed
    bool needed = false;
    for (int w = 0; w < shape.wide && !needed; ++w)
      for (uint32_t k = 0; k < changed && !needed; ++k) needed = p[(2 * w + 1) * changed + k] != 0;
    if (!needed) return CodecStatus::NonCanonical;
  }
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    const bool isActive = maskBit(d.activeMask, i);
    if (!isActive || !active[i]) symbols[i] = ProbeSymbols{};  // inactive, or newly active from black
    active[i] = isActive ? 1 : 0;
    if (!maskBit(d.changedMask, i)) continue;
    bool moved = false;
    for (int w = 0; w < shape.wide; ++w) {
      const uint32_t at = d.wideBytes * w * changed + k;
      const uint16_t z = static_cast<uint16_t>(p[at] | (d.wideBytes == 2 ? p[at + changed] << 8 : 0));
      symbols[i].wide[w] = static_cast<uint16_t>(symbols[i].wide[w] + unzigzag16(z));
      moved = moved || z != 0;
    }
    for (int j = 0; j < shape.narrow; ++j) {
      const uint8_t z = p[(d.wideBytes * shape.wide + j) * changed + k];
      symbols[i].narrow[j] = static_cast<uint8_t>(symbols[i].narrow[j] + unzigzag8(z));
      moved = moved || z != 0;
    }
    // Format 3: a probe is listed only when something of it changed (else it is one more spelling).
    if (!moved && formatVersion >= kCompactSectionFormat) return CodecStatus::NonCanonical;
    ++k;
  }
  return CodecStatus::Ok;
}

}  // namespace probecast
