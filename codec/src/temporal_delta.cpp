// Keyframe and delta payloads of one brick: masks, byte planes, zig-zag symbol differences.
#include <algorithm>
#include <cstring>

#include "brick_section.h"
#include "byte_io.h"
#include "probecast/codec/internal/rice_code.h"

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

// A delta's symbol differences, zig-zag coded, symbol-major: wide[w * changed + k] and
// narrow[j * changed + k] of the k-th changed probe.
struct DeltaSymbols {
  uint32_t changed = 0;
  SymbolShape shape{0, 0};
  std::vector<uint16_t> wide, narrow;
  void reset(uint32_t count, SymbolShape s) {
    changed = count;
    shape = s;
    wide.assign(static_cast<size_t>(count) * s.wide, 0);
    narrow.assign(static_cast<size_t>(count) * s.narrow, 0);
  }
  bool wideFitsOneByte() const {
    for (uint16_t z : wide)
      if (z >= 256) return false;
    return true;
  }
  size_t planeBytes() const { return changed * ((wideFitsOneByte() ? 1u : 2u) * shape.wide + shape.narrow); }
};

// The Rice spelling of a delta's differences (format 4): its parameters and its length in bytes.
struct RiceSpelling {
  int wideK = 0, narrowK = 0;
  size_t bytes = 0;
};

RiceSpelling riceSpelling(const DeltaSymbols& d) {
  RiceSpelling r;
  uint64_t wideBits = 0, narrowBits = 0;
  r.wideK = riceParameter(d.wide.data(), d.wide.size(), kRiceWideParameterBits, kRiceWideValueBits, &wideBits);
  r.narrowK =
      riceParameter(d.narrow.data(), d.narrow.size(), kRiceNarrowParameterBits, kRiceNarrowValueBits, &narrowBits);
  r.bytes = static_cast<size_t>((kRiceWideParameterBits + kRiceNarrowParameterBits + wideBits + narrowBits + 7) / 8);
  return r;
}

// Format 4 allows Rice codes only where they are shorter than byte planes (and byte planes anywhere).
bool riceIsShorter(const DeltaSymbols& d, const RiceSpelling& r) { return d.changed > 0 && r.bytes < d.planeBytes(); }

void appendRice(const DeltaSymbols& d, const RiceSpelling& r, std::vector<uint8_t>& out) {
  BitWriter bits(out);
  bits.put(static_cast<uint32_t>(r.wideK), kRiceWideParameterBits);
  bits.put(static_cast<uint32_t>(r.narrowK), kRiceNarrowParameterBits);
  for (uint32_t k = 0; k < d.changed; ++k) {
    for (int w = 0; w < d.shape.wide; ++w) bits.putRice(d.wide[w * d.changed + k], r.wideK, kRiceWideValueBits);
    for (int j = 0; j < d.shape.narrow; ++j)
      bits.putRice(d.narrow[j * d.changed + k], r.narrowK, kRiceNarrowValueBits);
  }
  bits.flush();
}

CodecStatus readRice(const uint8_t* data, size_t size, DeltaSymbols& d) {
  BitReader bits(data, size);
  uint32_t wideK = 0, narrowK = 0;
  if (!bits.get(kRiceWideParameterBits, &wideK) || !bits.get(kRiceNarrowParameterBits, &narrowK))
    return CodecStatus::SizeMismatch;
  uint16_t v = 0;
  for (uint32_t k = 0; k < d.changed; ++k) {
    for (int w = 0; w < d.shape.wide; ++w) {
      if (!bits.getRice(static_cast<int>(wideK), kRiceWideValueBits, &v)) return CodecStatus::NonCanonical;
      d.wide[w * d.changed + k] = v;
    }
    for (int j = 0; j < d.shape.narrow; ++j) {
      if (!bits.getRice(static_cast<int>(narrowK), kRiceNarrowValueBits, &v)) return CodecStatus::NonCanonical;
      d.narrow[j * d.changed + k] = v;
    }
  }
  if (!bits.atCleanEnd()) return CodecStatus::NonCanonical;  // stray bytes, or padding bits set
  const RiceSpelling best = riceSpelling(d);
  if (best.wideK != static_cast<int>(wideK) || best.narrowK != static_cast<int>(narrowK) || !riceIsShorter(d, best))
    return CodecStatus::NonCanonical;
  return CodecStatus::Ok;
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
                       const ProbeSymbols* base, const ProbeSymbols* next, std::vector<uint8_t>& out,
                       std::vector<uint8_t>* rice) {
  const SymbolShape shape = symbolShape(repr);
  const uint32_t mbytes = maskBytes(probes);
  const auto isChanged = [&](uint32_t i) {
    return active[i] && std::memcmp(&base[i], &next[i], sizeof(ProbeSymbols)) != 0;
  };
  uint32_t changed = 0;
  bool sameActive = true;
  for (uint32_t i = 0; i < probes; ++i) {
    sameActive = sameActive && (baseActive[i] != 0) == (active[i] != 0);
    changed += isChanged(i) ? 1 : 0;
  }
  thread_local DeltaSymbols d;
  d.reset(changed, shape);
  for (uint32_t i = 0, k = 0; i < probes; ++i) {
    if (!isChanged(i)) continue;
    for (int w = 0; w < shape.wide; ++w)
      d.wide[w * changed + k] = zigzag16(static_cast<uint16_t>(next[i].wide[w] - base[i].wide[w]));
    for (int j = 0; j < shape.narrow; ++j)
      d.narrow[j * changed + k] = zigzag8(static_cast<uint8_t>(next[i].narrow[j] - base[i].narrow[j]));
    ++k;
  }
  const bool narrowWide = d.wideFitsOneByte();
  const bool list = probes <= 256 && 1 + changed < mbytes;
  out.clear();
  out.push_back(static_cast<uint8_t>((sameActive ? 0 : kDeltaActiveMask) | (list ? kDeltaChangedList : 0) |
                                     (narrowWide ? kDeltaNarrowWide : 0)));
  if (!sameActive) appendMask(probes, active, out);
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
  if (rice != nullptr) {
    rice->clear();
    const RiceSpelling spelling = riceSpelling(d);
    if (riceIsShorter(d, spelling)) {
      rice->assign(out.begin(), out.end());
      (*rice)[0] = static_cast<uint8_t>(((*rice)[0] & ~kDeltaNarrowWide) | kDeltaRice);
      appendRice(d, spelling, *rice);
    }
  }
  // Planes: each wide difference's low byte (and high byte unless all fit one), then the narrow ones.
  const uint32_t wideBytes = narrowWide ? 1 : 2;
  for (int w = 0; w < shape.wide; ++w) {
    for (uint32_t k = 0; k < changed; ++k) out.push_back(static_cast<uint8_t>(d.wide[w * changed + k] & 0xff));
    if (wideBytes == 2)
      for (uint32_t k = 0; k < changed; ++k) out.push_back(static_cast<uint8_t>(d.wide[w * changed + k] >> 8));
  }
  for (int j = 0; j < shape.narrow; ++j)
    for (uint32_t k = 0; k < changed; ++k) out.push_back(static_cast<uint8_t>(d.narrow[j * changed + k]));
}

namespace {

// A delta's masks and where its planes start, whatever the format spelled them as.
struct DeltaForm {
  uint8_t activeMask[kMaxBrickProbes / 8] = {};
  uint8_t changedMask[kMaxBrickProbes / 8] = {};
  uint32_t changed = 0;
  uint32_t wideBytes = 2;
  bool rice = false;  // format 4: the differences as Rice codes
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
CodecStatus readCompactDelta(uint8_t formatVersion, uint32_t probes, const uint8_t* baseActive, const uint8_t* raw,
                             size_t rawSize, DeltaForm& d) {
  const uint32_t mbytes = maskBytes(probes);
  if (rawSize < 1) return CodecStatus::SizeMismatch;
  const uint8_t form = raw[0];
  const uint8_t known = kDeltaActiveMask | kDeltaChangedList | kDeltaNarrowWide |
                        (formatVersion >= kRiceDeltaFormat ? kDeltaRice : 0);
  if ((form & ~known) || ((form & kDeltaRice) && (form & kDeltaNarrowWide))) return CodecStatus::NonCanonical;
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
  d.rice = (form & kDeltaRice) != 0;
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
  const CodecStatus form = formatVersion >= kCompactSectionFormat ? readCompactDelta(formatVersion, probes, active, raw, rawSize, d)
                                                                   : readFixedDelta(probes, raw, rawSize, d);
  if (form != CodecStatus::Ok) return form;
  if (!maskTailIsClear(d.activeMask, probes)) return CodecStatus::BadMask;
  for (uint32_t b = 0; b < mbytes; ++b)
    if (d.changedMask[b] & ~d.activeMask[b]) return CodecStatus::BadMask;
  const SymbolShape shape = symbolShape(repr);
  const uint32_t changed = d.changed;
  thread_local DeltaSymbols z;
  z.reset(changed, shape);
  if (d.rice) {
    if (CodecStatus st = readRice(d.planes, d.planeBytes, z); st != CodecStatus::Ok) return st;
  } else {
    if (d.planeBytes != changed * (d.wideBytes * shape.wide + shape.narrow)) return CodecStatus::SizeMismatch;
    const uint8_t* p = d.planes;
    for (int w = 0; w < shape.wide; ++w)
      for (uint32_t k = 0; k < changed; ++k) {
        const uint32_t at = d.wideBytes * w * changed + k;
        z.wide[w * changed + k] = static_cast<uint16_t>(p[at] | (d.wideBytes == 2 ? p[at + changed] << 8 : 0));
      }
    for (int j = 0; j < shape.narrow; ++j)
      for (uint32_t k = 0; k < changed; ++k) z.narrow[j * changed + k] = p[(d.wideBytes * shape.wide + j) * changed + k];
    // The high bytes are spelled out only when one is needed.
    if (d.wideBytes == 2 && formatVersion >= kCompactSectionFormat && z.wideFitsOneByte()) return CodecStatus::NonCanonical;
  }
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    const bool isActive = maskBit(d.activeMask, i);
    if (!isActive || !active[i]) symbols[i] = ProbeSymbols{};  // inactive, or newly active from black
    active[i] = isActive ? 1 : 0;
    if (!maskBit(d.changedMask, i)) continue;
    bool moved = false;
    for (int w = 0; w < shape.wide; ++w) {
      const uint16_t v = z.wide[w * changed + k];
      symbols[i].wide[w] = static_cast<uint16_t>(symbols[i].wide[w] + unzigzag16(v));
      moved = moved || v != 0;
    }
    for (int j = 0; j < shape.narrow; ++j) {
      const uint8_t v = static_cast<uint8_t>(z.narrow[j * changed + k]);
      symbols[i].narrow[j] = static_cast<uint8_t>(symbols[i].narrow[j] + unzigzag8(v));
      moved = moved || v != 0;
    }
    // Format 3: a probe is listed only when something of it changed (else it is one more spelling).
    if (!moved && formatVersion >= kCompactSectionFormat) return CodecStatus::NonCanonical;
    ++k;
  }
  return CodecStatus::Ok;
}

}  // namespace probecast
