// crc32Of (worker/crc32.h): every method this CPU has gives zlib's CRC-32, for every length
// 0..4096 at every alignment 0..15, for long buffers, and for all-zero and all-one bytes (the
// value on the wire and in journals must not depend on the machine).
#include <gtest/gtest.h>
#include <zlib.h>

#include <random>
#include <string>
#include <vector>

#include "frep/farm/crc32.h"

using namespace frep::farm;

namespace {
uint32_t zlibCrc(const unsigned char* p, size_t n) { return uint32_t(crc32(0L, p, uInt(n))); }

std::vector<unsigned char> randomBytes(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<unsigned char> b(n);
  for (auto& c : b) c = static_cast<unsigned char>(rng());
  return b;
}
}  // namespace

TEST(Crc32, KnownValue) {
  for (Crc32Method m : crc32Methods()) EXPECT_EQ(crc32With(m, "123456789", 9), 0xCBF43926u);  // CRC-32's check value
  const std::string text(1000, 'x');  // long enough for every folding method
  EXPECT_EQ(crc32Of(text.data(), text.size()), zlibCrc(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

TEST(Crc32, EveryMethodGivesZlibsValueAtEveryLengthAndAlignment) {
  const std::vector<unsigned char> bytes = randomBytes(4096 + 16, 17);
  const std::vector<Crc32Method> methods = crc32Methods();
  std::printf("CRC-32 methods on this CPU: %zu (zlib, PCLMULQDQ, VPCLMULQDQ)\n", methods.size());
  for (size_t n = 0; n <= 4096; ++n)
    for (size_t offset = 0; offset < 16; ++offset) {
      const uint32_t want = zlibCrc(bytes.data() + offset, n);
      for (Crc32Method m : methods)
        ASSERT_EQ(crc32With(m, bytes.data() + offset, n), want) << "method " << int(m) << ", " << n << " bytes at +" << offset;
    }
}

TEST(Crc32, LongAndUniformBuffers) {
  std::vector<std::vector<unsigned char>> buffers{randomBytes(1 << 20, 5), randomBytes(150001, 6),
                                                  std::vector<unsigned char>(70000, 0),
                                                  std::vector<unsigned char>(70000, 0xFF)};
  for (const auto& b : buffers) {
    const uint32_t want = zlibCrc(b.data(), b.size());
    for (Crc32Method m : crc32Methods()) EXPECT_EQ(crc32With(m, b.data(), b.size()), want) << int(m);
    EXPECT_EQ(crc32Of(b.data(), b.size()), want);
  }
}

TEST(Crc32, ASingleFlippedBitChangesIt) {
  std::vector<unsigned char> b = randomBytes(5000, 9);
  for (Crc32Method m : crc32Methods()) {
    const uint32_t before = crc32With(m, b.data(), b.size());
    for (size_t bit : {size_t(0), size_t(31), size_t(4000), size_t(8 * 5000 - 1)}) {
      b[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
      EXPECT_NE(crc32With(m, b.data(), b.size()), before) << int(m) << " bit " << bit;
      EXPECT_EQ(crc32With(m, b.data(), b.size()), zlibCrc(b.data(), b.size()));
      b[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
    }
  }
}
