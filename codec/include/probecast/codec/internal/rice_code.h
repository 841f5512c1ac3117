// Rice codes of a delta's symbol differences (format 4, stream.h). Internal to the codec; here,
// under probecast/codec/internal/, for its tests.
//
// A value v (a zig-zag difference) under parameter k is its quotient q = v >> k in unary (q one
// bits, then a zero bit) and its k low bits; a quotient of kRiceEscapeQuotient or more is instead
// that many one bits and v in full (16 bits for a wide symbol, 8 for a narrow one). Bits are packed
// low first within each byte. Each value has one spelling: escaped exactly when its quotient reaches
// the escape.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace probecast {

constexpr uint32_t kRiceEscapeQuotient = 8;
constexpr int kRiceWideParameterBits = 4;    // k of the wide differences: 0..15
constexpr int kRiceNarrowParameterBits = 3;  // k of the narrow differences: 0..7
constexpr int kRiceWideValueBits = 16;
constexpr int kRiceNarrowValueBits = 8;

// The parameter (0 .. 2^parameterBits − 1) under which `values` take the fewest bits, the smallest
// such k on ties (so a set of values has one parameter); its bit count into *bits.
int riceParameter(const uint16_t* values, size_t count, int parameterBits, int valueBits, uint64_t* bits);

class BitWriter {
 public:
  explicit BitWriter(std::vector<uint8_t>& out) : out_(out) {}
  void put(uint32_t value, int bits) {  // bits <= 24
    pending_ |= static_cast<uint64_t>(value & ((1u << bits) - 1u)) << pendingBits_;
    pendingBits_ += bits;
    while (pendingBits_ >= 8) {
      out_.push_back(static_cast<uint8_t>(pending_));
      pending_ >>= 8;
      pendingBits_ -= 8;
    }
  }
  void putRice(uint16_t value, int k, int valueBits) {
    const uint32_t q = static_cast<uint32_t>(value) >> k;
    if (q >= kRiceEscapeQuotient) {  // eight ones, then the value in full
      put((1u << kRiceEscapeQuotient) - 1u, kRiceEscapeQuotient);
      put(value, valueBits);
    } else {  // q ones, the zero, then the k low bits: at most 8 + 15 bits
      put(((static_cast<uint32_t>(value) & ((1u << k) - 1u)) << (q + 1)) | ((1u << q) - 1u), static_cast<int>(q) + 1 + k);
    }
  }
  void flush();  // pads the last byte with zero bits

 private:
  std::vector<uint8_t>& out_;
  uint64_t pending_ = 0;
  int pendingBits_ = 0;
};

class BitReader {
 public:
  BitReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool get(int bits, uint32_t* value);  // false when the data ends first
  // A Rice value; false when the data ends first or it is not in its one spelling (an escape whose
  // quotient is below the escape, a value wider than valueBits).
  bool getRice(int k, int valueBits, uint16_t* value);
  // Whether what is left is the zero padding of the last byte and nothing more.
  bool atCleanEnd() const;

 private:
  const uint8_t* data_;
  size_t size_;
  size_t bit_ = 0;
};

}  // namespace probecast
