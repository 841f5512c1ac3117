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

void buildDeltaPayload(Representation repr, uint32_t probes, const uint8_t* active, const ProbeSymbols* base,
                       const ProbeSymbols* next, std::vector<uint8_t>& out) {
  const SymbolShape shape = symbolShape(repr);
  out.clear();
  appendMask(probes, active, out);
  const size_t changedAt = out.size();
  out.resize(changedAt + maskBytes(probes), 0);
  uint32_t changed = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    if (active[i] && std::memcmp(&base[i], &next[i], sizeof(ProbeSymbols)) != 0) {
      setMaskBit(out.data() + changedAt, i);
      ++changed;
    }
  }
  const size_t planes = out.size();
  out.resize(planes + changed * (2u * shape.wide + shape.narrow));
  uint8_t* p = out.data() + planes;
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    if (!maskBit(out.data() + changedAt, i)) continue;
    for (int w = 0; w < shape.wide; ++w) {
      const uint16_t z = zigzag16(static_cast<uint16_t>(next[i].wide[w] - base[i].wide[w]));
      p[(2 * w) * changed + k] = static_cast<uint8_t>(z & 0xff);
      p[(2 * w + 1) * changed + k] = static_cast<uint8_t>(z >> 8);
    }
    for (int j = 0; j < shape.narrow; ++j)
      p[(2 * shape.wide + j) * changed + k] = zigzag8(static_cast<uint8_t>(next[i].narrow[j] - base[i].narrow[j]));
    ++k;
  }
}

CodecStatus applyPayload(Representation repr, uint32_t probes, SectionKind kind, const uint8_t* raw, size_t rawSize,
                         uint8_t* active, ProbeSymbols* symbols) {
  const uint32_t mbytes = maskBytes(probes);
  if (rawSize < mbytes) return CodecStatus::SizeMismatch;
  const uint8_t* activeMask = raw;
  if (!maskTailIsClear(activeMask, probes)) return CodecStatus::BadMask;

  if (kind == SectionKind::Keyframe) {
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

  const SymbolShape shape = symbolShape(repr);
  if (rawSize < 2u * mbytes) return CodecStatus::SizeMismatch;
  const uint8_t* changedMask = raw + mbytes;
  if (!maskTailIsClear(changedMask, probes)) return CodecStatus::BadMask;
  for (uint32_t b = 0; b < mbytes; ++b)
    if (changedMask[b] & ~activeMask[b]) return CodecStatus::BadMask;
  const uint32_t changed = popcount(changedMask, mbytes);
  if (rawSize != 2u * mbytes + changed * (2u * shape.wide + shape.narrow)) return CodecStatus::SizeMismatch;
  const uint8_t* p = raw + 2u * mbytes;
  uint32_t k = 0;
  for (uint32_t i = 0; i < probes; ++i) {
    const bool isActive = maskBit(activeMask, i);
    if (!isActive || !active[i]) symbols[i] = ProbeSymbols{};  // inactive, or newly active from black
    active[i] = isActive ? 1 : 0;
    if (!maskBit(changedMask, i)) continue;
    for (int w = 0; w < shape.wide; ++w) {
      const uint16_t z = static_cast<uint16_t>(p[(2 * w) * changed + k] | (p[(2 * w + 1) * changed + k] << 8));
      symbols[i].wide[w] = static_cast<uint16_t>(symbols[i].wide[w] + unzigzag16(z));
    }
    for (int j = 0; j < shape.narrow; ++j)
      symbols[i].narrow[j] =
          static_cast<uint8_t>(symbols[i].narrow[j] + unzigzag8(p[(2 * shape.wide + j) * changed + k]));
    ++k;
  }
  return CodecStatus::Ok;
}

}  // namespace probecast
