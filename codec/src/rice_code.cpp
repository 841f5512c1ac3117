#include "probecast/codec/internal/rice_code.h"

namespace probecast {

int riceParameter(const uint16_t* values, size_t count, int parameterBits, int valueBits, uint64_t* bits) {
  // One pass instead of one per k. A value of bit length L is escaped for k <= L - 4 (its quotient
  // v >> k is 8 or more), spelled with quotient v >> k in 1..7 for L - 3 <= k < L, and with quotient 0
  // for k >= L; so each k's bits are the escaped values' full spellings, every other value's 1 + k,
  // and the quotients of the values in their middle band.
  constexpr int kMaxK = 16;
  uint64_t lengths[kMaxK + 2] = {};  // values per bit length 0..16
  uint64_t quotients[kMaxK] = {};    // per k: the sum of v >> k over values with L - 3 <= k < L
  for (size_t i = 0; i < count; ++i) {
    const uint32_t v = values[i];
    const int length = v == 0 ? 0 : 32 - __builtin_clz(v);
    ++lengths[length];
    for (int k = length > 3 ? length - 3 : 0; k < length; ++k) quotients[k] += v >> k;
  }
  const int ks = 1 << parameterBits;
  int best = 0;
  uint64_t bestBits = 0;
  uint64_t escaped = 0;  // values of bit length >= k + 4
  for (int length = 4; length <= kMaxK; ++length) escaped += lengths[length];
  for (int k = 0; k < ks; ++k) {
    const uint64_t b = escaped * (kRiceEscapeQuotient + static_cast<uint64_t>(valueBits)) +
                       (count - escaped) * (1 + static_cast<uint64_t>(k)) + quotients[k];
    if (k == 0 || b < bestBits) {
      best = k;
      bestBits = b;
    }
    if (k + 4 <= kMaxK) escaped -= lengths[k + 4];
  }
  *bits = bestBits;
  return best;
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
