// The codec's CRC-32C: known answers, and the fast form equal to the table form everywhere.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "probecast/codec/internal/crc32c.h"

namespace probecast {
namespace {

TEST(Crc32c, KnownAnswers) {
  // The check value of CRC-32C ("123456789"), and RFC 3720 B.4's 32 bytes of zeros and of 0xff.
  const uint8_t digits[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc32c(digits, sizeof digits), 0xE3069283u);
  EXPECT_EQ(crc32cPortable(digits, sizeof digits), 0xE3069283u);
  const std::vector<uint8_t> zeros(32, 0), ones(32, 0xff);
  EXPECT_EQ(crc32c(zeros.data(), zeros.size()), 0x8A9136AAu);
  EXPECT_EQ(crc32c(ones.data(), ones.size()), 0x62A8AB43u);
  EXPECT_EQ(crc32c(nullptr, 0), 0u);
}

TEST(Crc32c, FastFormEqualsTableFormAtEveryLengthAndAlignment) {
  std::mt19937 rng(3);
  std::vector<uint8_t> bytes(4096 + 16);
  for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
  for (size_t offset = 0; offset < 9; ++offset)
    for (size_t size : {0, 1, 7, 8, 9, 15, 16, 17, 63, 64, 100, 1000, 4096}) {
      const uint8_t* p = bytes.data() + offset;
      ASSERT_EQ(crc32c(p, size), crc32cPortable(p, size)) << "offset " << offset << " size " << size;
      ASSERT_EQ(crc32c(p, size, 0x12345678u), crc32cPortable(p, size, 0x12345678u));
    }
  // Continuing over a second buffer is the CRC of the two together.
  const uint32_t whole = crc32c(bytes.data(), 1000);
  EXPECT_EQ(crc32c(bytes.data() + 300, 700, crc32c(bytes.data(), 300)), whole);
}

}  // namespace
}  // namespace probecast
