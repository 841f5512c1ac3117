// Rice codes of format 4 deltas (internal/rice_code.h): the parameter is the best of every k, every
// value round-trips under every k, and only the one spelling of a value is read.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "probecast/codec/internal/rice_code.h"

namespace probecast {
namespace {

// The bits of one k, counted value by value from the definition (the parameter search counts all k
// in one pass).
uint64_t bitsAt(const std::vector<uint16_t>& values, int k, int valueBits) {
  uint64_t bits = 0;
  for (uint32_t v : values) bits += (v >> k) >= 8 ? 8 + valueBits : (v >> k) + 1 + k;
  return bits;
}

TEST(RiceCode, ParameterIsTheSmallestOfTheCheapestK) {
  std::mt19937 rng(11);
  for (int t = 0; t < 20000; ++t) {
    const bool wide = t % 2 == 0;
    const int valueBits = wide ? 16 : 8, parameterBits = wide ? 4 : 3;
    std::vector<uint16_t> values(rng() % 40);
    const uint32_t range = 1u << (rng() % (valueBits + 1));  // small and large values alike
    for (uint16_t& v : values) v = static_cast<uint16_t>(rng() % range);
    int best = 0;
    for (int k = 1; k < (1 << parameterBits); ++k)
      if (bitsAt(values, k, valueBits) < bitsAt(values, best, valueBits)) best = k;
    uint64_t bits = 0;
    ASSERT_EQ(riceParameter(values.data(), values.size(), parameterBits, valueBits, &bits), best) << t;
    ASSERT_EQ(bits, bitsAt(values, best, valueBits)) << t;
  }
}

TEST(RiceCode, EveryValueRoundTripsUnderEveryParameter) {
  for (const int valueBits : {8, 16}) {
    for (int k = 0; k < (valueBits == 8 ? 8 : 16); ++k) {
      std::vector<uint16_t> values;
      for (uint32_t v = 0; v < (1u << valueBits); v += valueBits == 8 ? 1 : 7) values.push_back(static_cast<uint16_t>(v));
      values.push_back(static_cast<uint16_t>((1u << valueBits) - 1));
      std::vector<uint8_t> bytes;
      BitWriter writer(bytes);
      for (uint16_t v : values) writer.putRice(v, k, valueBits);
      writer.flush();
      EXPECT_EQ(bytes.size(), (bitsAt(values, k, valueBits) + 7) / 8);
      BitReader reader(bytes.data(), bytes.size());
      for (uint16_t v : values) {
        uint16_t read = 0;
        ASSERT_TRUE(reader.getRice(k, valueBits, &read)) << valueBits << " k " << k << " v " << v;
        ASSERT_EQ(read, v) << valueBits << " k " << k;
      }
      EXPECT_TRUE(reader.atCleanEnd());
    }
  }
}

TEST(RiceCode, OnlyTheOneSpellingIsRead) {
  const auto read = [](const std::vector<uint8_t>& bytes, int k, int valueBits, uint16_t* v) {
    BitReader reader(bytes.data(), bytes.size());
    return reader.getRice(k, valueBits, v) && reader.atCleanEnd();
  };
  uint16_t v = 0;
  // 5 under k = 0 escaped (eight ones, then 5 in 8 bits): its quotient is below the escape.
  EXPECT_FALSE(read({0xff, 0x05}, 0, 8, &v));
  // 200 under k = 0: eight ones, then 200 in 8 bits.
  EXPECT_TRUE(read({0xff, 200}, 0, 8, &v));
  EXPECT_EQ(v, 200);
  // Quotient 7 and k = 7 low bits of all ones: 1023, wider than a narrow value.
  EXPECT_FALSE(read({0x7f, 0xff}, 7, 8, &v));
  // Cut off inside the escaped value; a padding bit set; a byte after the code.
  EXPECT_FALSE(read({0xff}, 0, 8, &v));
  EXPECT_FALSE(read({0x02}, 0, 8, &v));  // 0 (one zero bit), then a stray 1
  EXPECT_FALSE(read({0x00, 0x00}, 0, 8, &v));
  EXPECT_TRUE(read({0x00}, 0, 8, &v));
  EXPECT_EQ(v, 0);
}

}  // namespace
}  // namespace probecast
