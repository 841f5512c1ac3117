#include "probecast/codec/crc32c.h"

#include <array>
#include <cstring>

#if defined(__x86_64__)
#include <nmmintrin.h>
#endif

namespace probecast {
namespace {

constexpr std::array<uint32_t, 256> makeTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr std::array<uint32_t, 256> kTable = makeTable();

#if defined(__x86_64__)
// SSE4.2's crc32 computes exactly this polynomial, 8 bytes per instruction: a load test checks
// every frame it receives, and the table walk (a byte per lookup) was most of its time.
__attribute__((target("sse4.2"))) uint32_t crc32cSse42(const uint8_t* data, size_t size, uint32_t crc) {
  uint64_t c = ~crc;
  for (; size > 0 && reinterpret_cast<uintptr_t>(data) % 8 != 0; --size) c = _mm_crc32_u8(static_cast<uint32_t>(c), *data++);
  for (; size >= 8; size -= 8, data += 8) {
    uint64_t word;
    std::memcpy(&word, data, 8);
    c = _mm_crc32_u64(c, word);
  }
  for (; size > 0; --size) c = _mm_crc32_u8(static_cast<uint32_t>(c), *data++);
  return ~static_cast<uint32_t>(c);
}

const bool kHaveSse42 = __builtin_cpu_supports("sse4.2");
#endif

}  // namespace

uint32_t crc32cPortable(const uint8_t* data, size_t size, uint32_t crc) {
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = kTable[(crc ^ data[i]) & 0xffu] ^ (crc >> 8);
  return ~crc;
}

uint32_t crc32c(const uint8_t* data, size_t size, uint32_t crc) {
#if defined(__x86_64__)
  if (kHaveSse42) return crc32cSse42(data, size, crc);
#endif
  return crc32cPortable(data, size, crc);
}

}  // namespace probecast
