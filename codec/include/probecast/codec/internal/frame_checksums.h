// Test support, not part of the embedding API: headers under probecast/codec/internal/ exist for
// the project's tests and fuzz targets only and may change without notice.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace probecast {

// Recomputes the header CRC and every section CRC of a (possibly corrupted) frame in place, so
// tests and the fuzzer can reach the parsers behind the checksums. Not for production use.
void rewriteFrameChecksums(std::vector<uint8_t>& frame);

// Where the fields of a format 3 section at section[0..size) lie; false when its varints do not
// parse or its data runs past `size`. Nothing is checked against a layout or the CRC.
struct SectionBytes {
  size_t kindAt = 0;  // the kind byte
  size_t crcAt = 0;   // the CRC, just before the data
  size_t dataAt = 0;
  uint32_t storedSize = 0;
};
bool locateSection(const uint8_t* section, size_t size, SectionBytes* out);

// A format 3 section holding `data` as given under `kindByte` (verbatim), with a valid CRC, so
// tests can put any payload behind a well-formed header.
std::vector<uint8_t> sealSection(uint32_t brick, uint32_t version, uint8_t kindByte, std::span<const uint8_t> data);

}  // namespace probecast
