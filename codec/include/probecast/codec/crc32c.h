// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), as used by iSCSI and ext4.
#pragma once

#include <cstddef>
#include <cstdint>

namespace probecast {

uint32_t crc32c(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace probecast
