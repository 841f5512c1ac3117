// Little-endian reads and writes with explicit bounds (private to the codec).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace probecast {

inline void putU16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v));
  out.push_back(static_cast<uint8_t>(v >> 8));
}
inline void putU32(std::vector<uint8_t>& out, uint32_t v) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<uint8_t>(v >> (8 * b)));
}
inline uint16_t getU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
inline uint32_t getU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) | (static_cast<uint32_t>(p[2]) << 16) |
         (static_cast<uint32_t>(p[3]) << 24);
}
inline void setU32(uint8_t* p, uint32_t v) {
  for (int b = 0; b < 4; ++b) p[b] = static_cast<uint8_t>(v >> (8 * b));
}

// Unsigned LEB128: 7 bits a byte, low first, the top bit set on every byte but the last.
inline void putVarint(std::vector<uint8_t>& out, uint32_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<uint8_t>(v));
}
// Reads a varint from p[0..size): the bytes it took, or 0 when it is cut off, longer than a
// uint32_t holds, or not in its shortest form (so every value has exactly one encoding).
inline size_t getVarint(const uint8_t* p, size_t size, uint32_t* v) {
  uint64_t value = 0;
  for (size_t i = 0; i < size && i < 5; ++i) {
    value |= static_cast<uint64_t>(p[i] & 0x7f) << (7 * i);
    if (p[i] & 0x80) continue;
    if ((i > 0 && p[i] == 0) || value > 0xffffffffu) return 0;
    *v = static_cast<uint32_t>(value);
    return i + 1;
  }
  return 0;
}

inline uint16_t zigzag16(int v) { return static_cast<uint16_t>((static_cast<int16_t>(v) * 2) ^ (static_cast<int16_t>(v) >> 15)); }
inline int unzigzag16(uint16_t v) { return static_cast<int16_t>(static_cast<uint16_t>((v >> 1) ^ (0u - (v & 1u)))); }
inline uint8_t zigzag8(int v) { return static_cast<uint8_t>((static_cast<int8_t>(v) * 2) ^ (static_cast<int8_t>(v) >> 7)); }
inline int unzigzag8(uint8_t v) { return static_cast<int8_t>(static_cast<uint8_t>((v >> 1) ^ (0u - (v & 1u)))); }

}  // namespace probecast
