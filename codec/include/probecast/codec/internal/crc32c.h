// Test support, not part of the embedding API (see frame_checksums.h): the codec's CRC-32C.
#pragma once

#include <cstddef>
#include <cstdint>

namespace probecast {

// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), as used by iSCSI and ext4; `crc` is the
// value so far, to continue over a second buffer. The processor's crc32 instruction where there
// is one (x86-64 with SSE4.2), else crc32cPortable: the same value either way.
uint32_t crc32c(const uint8_t* data, size_t size, uint32_t crc = 0);
// The table-driven form, on every processor (the reference the fast one is tested against).
uint32_t crc32cPortable(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace probecast
