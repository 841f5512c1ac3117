#include "rice_code.h"

namespace probecast {

uint64_t riceBits(const uint16_t* values, size_t count, int k, int valueBits) {
  uint64_t bits = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t q = static_cast<uint32_t>(values[i]) >> k;
    bits += q < kRiceEscapeQuotient ? q + 1 + static_cast<uint32_t>(k) : kRiceEscapeQuotient + static_cast<uint32_t>(valueBits);
  }
  return bits;
}

int riceParameter(const uint16_t* values, size_t count, int parameterBits, int valueBits, uint64_t* bits) {
  int best = 0;
  uint64_t bestBits = riceBits(values, count, 0, valueBits);
  for (int k = 1; k < (1 << parameterBits); ++k) {
    const uint64_t b = riceBits(values, count, k, valueBits);
    if (b < bestBits) {
      best = k;
      bestBits = b;
    }
  }
  *bits = bestBits;
  return best;
}

void BitWriter::put(uint32_t value, int bits) {
  pending_ |= static_cast<uint64_t>(value & ((1u << bits) - 1u)) << pendingBits_;
  pendingBits_ += bits;
  while (pendingBits_ >= 8) {
    out_.push_back(static_cast<uint8_t>(pending_));
    pending_ >>= 8;
    pendingBits_ -= 8;
  }
}

void BitWriter::putRice(uint16_t value, int k, int valueBits) {
  const uint32_t q = static_cast<uint32_t>(value) >> k;
  if (q >= kRiceEscapeQuotient) {
    put((1u << kRiceEscapeQuotient) - 1u, kRiceEscapeQuotient);
    put(value, valueBits);
    return;
  }
  put((1u << q) - 1u, static_cast<int>(q) + 1);  // q ones, then the zero
  if (k > 0) put(value, k);
}

void BitWriter::flush() {
  if (pendingBits_ > 0) out_.push_back(static_cast<uint8_t>(pending_));
  pending_ = 0;
  pendingBits_ = 0;
}

bool BitReader::get(int bits, uint32_t* value) {
  if (bits > 0 && (size_ * 8 - bit_) < static_cast<size_t>(bits)) return false;
  uint32_t v = 0;
  for (int i = 0; i < bits; ++i, ++bit_) v |= static_cast<uint32_t>((data_[bit_ >> 3] >> (bit_ & 7)) & 1u) << i;
  *value = v;
  return true;
}

bool BitReader::getRice(int k, int valueBits, uint16_t* value) {
  uint32_t q = 0, bit = 1;
  while (q < kRiceEscapeQuotient) {
    if (!get(1, &bit)) return false;
    if (!bit) break;
    ++q;
  }
  uint32_t v = 0;
  if (q == kRiceEscapeQuotient) {
    if (!get(valueBits, &v) || (v >> k) < kRiceEscapeQuotient) return false;  // would have been spelled directly
  } else {
    uint32_t low = 0;
    if (!get(k, &low)) return false;
    v = (q << k) | low;
    if (v >> valueBits) return false;
  }
  *value = static_cast<uint16_t>(v);
  return true;
}

bool BitReader::atCleanEnd() const {
  if ((bit_ + 7) / 8 != size_) return false;
  if ((bit_ & 7) == 0) return true;
  return (data_[bit_ >> 3] >> (bit_ & 7)) == 0;
}

}  // namespace probecast
