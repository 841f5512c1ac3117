// Test support, not part of the embedding API: headers under probecast/codec/internal/ exist for
// the project's tests and fuzz targets only and may change without notice.
#pragma once

#include <cstdint>
#include <vector>

namespace probecast {

// Recomputes the header CRC and every section CRC of a (possibly corrupted) frame in place, so
// tests and the fuzzer can reach the parsers behind the checksums. Not for production use.
void rewriteFrameChecksums(std::vector<uint8_t>& frame);

}  // namespace probecast
