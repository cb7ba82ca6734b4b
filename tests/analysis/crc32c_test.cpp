// CRC-32C: the published check values, and the fast paths (CPU instruction, slicing-by-8)
// against a bit-at-a-time reference written from the definition, on every length and
// alignment that exercises their word loops and tails.
#include "cal/analysis/crc32c.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string_view>
#include <vector>

namespace {

std::span<const std::byte> bytes(std::string_view s) {
  return std::as_bytes(std::span(s.data(), s.size()));
}

// The definition: reflected polynomial 0x82F63B78, register preset to all ones, result
// inverted; one bit per step.
std::uint32_t reference(std::span<const std::byte> data) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::byte b : data) {
    c ^= static_cast<std::uint8_t>(b);
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
  }
  return ~c;
}

TEST(Crc32c, PublishedCheckValues) {
  // RFC 3720 (iSCSI), appendix B.4 "CRC Examples": 32 bytes of zeros, of ones, ascending
  // 0x00..0x1F and descending 0x1F..0x00; and the catalogue check value of "123456789".
  std::array<std::byte, 32> zeros{}, ones{}, up{}, down{};
  ones.fill(std::byte{0xFF});
  for (std::size_t i = 0; i < 32; ++i) {
    up[i] = static_cast<std::byte>(i);
    down[i] = static_cast<std::byte>(31 - i);
  }
  for (auto f : {&cal::crc32c, &cal::crc32c_portable}) {
    EXPECT_EQ(f(zeros, 0), 0x8A9136AAu);
    EXPECT_EQ(f(ones, 0), 0x62A8AB43u);
    EXPECT_EQ(f(up, 0), 0x46DD794Eu);
    EXPECT_EQ(f(down, 0), 0x113FDB5Cu);
    EXPECT_EQ(f(bytes("123456789"), 0), 0xE3069283u);
    EXPECT_EQ(f({}, 0), 0u);
  }
  EXPECT_EQ(reference(bytes("123456789")), 0xE3069283u);  // the reference itself
}

TEST(Crc32c, FastPathsEqualTheBitwiseDefinitionAtEveryLengthAndAlignment) {
  std::mt19937 rng(20);
  std::vector<std::byte> buf(600);
  for (auto& b : buf) b = static_cast<std::byte>(rng());
  for (std::size_t offset = 0; offset < 8; ++offset)
    for (std::size_t n = 0; offset + n <= 300; ++n) {
      const auto s = std::span<const std::byte>(buf).subspan(offset, n);
      const auto want = reference(s);
      ASSERT_EQ(cal::crc32c(s), want) << offset << " " << n;
      ASSERT_EQ(cal::crc32c_portable(s), want) << offset << " " << n;
    }
}

TEST(Crc32c, ContinuesAcrossPieces) {
  std::mt19937 rng(3);
  std::vector<std::byte> buf(4096 + 13);
  for (auto& b : buf) b = static_cast<std::byte>(rng());
  const auto whole = reference(buf);
  for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{8},
                          std::size_t{1000}, buf.size()}) {
    const auto head = std::span<const std::byte>(buf).first(cut);
    const auto tail = std::span<const std::byte>(buf).subspan(cut);
    EXPECT_EQ(cal::crc32c(tail, cal::crc32c(head)), whole) << cut;
    EXPECT_EQ(cal::crc32c_portable(tail, cal::crc32c_portable(head)), whole) << cut;
  }
}

}  // namespace
