// expandCompactLeaf (worker/leaf_expand.h): every way this CPU has gives the bits of the
// reference expansion written here voxel by voxel, for any active and sign masks and any m
// (its sign bit set too), uses 4 bytes per active voxel, and reads nothing past them.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <random>

#include "frep/farm/leaf_expand.h"

using namespace frep::farm;

namespace {
// The format's definition, one voxel at a time.
std::vector<uint32_t> reference(const uint64_t active[8], const uint64_t positive[8], uint32_t m, const uint32_t* stream) {
  std::vector<uint32_t> v(512);
  for (int i = 0; i < 512; ++i) {
    const bool on = (active[i >> 6] >> (i & 63)) & 1u, plus = (positive[i >> 6] >> (i & 63)) & 1u;
    v[size_t(i)] = on ? *stream++ : (plus ? m : m ^ 0x80000000u);
  }
  return v;
}
}  // namespace

TEST(LeafExpand, EveryWayGivesTheFormatsBitsAndReadsOnlyItsValues) {
  std::mt19937_64 rng(11);
  const long page = sysconf(_SC_PAGESIZE);
  // The stream ends where an unreadable page begins: reading one byte past it would crash.
  char* pages = static_cast<char*>(mmap(nullptr, size_t(3 * page), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(pages, MAP_FAILED);
  ASSERT_EQ(mprotect(pages + 2 * page, size_t(page), PROT_NONE), 0);
  for (int trial = 0; trial < 400; ++trial) {
    uint64_t active[8], positive[8];
    const int density = trial % 6;  // none, sparse, half, dense, all, rows of 8 all or none
    for (int w = 0; w < 8; ++w) {
      const uint64_t a = rng(), b = rng(), c = rng();
      active[w] = density == 0 ? 0 : density == 1 ? a & b & c : density == 2 ? a : density == 3 ? a | b : density == 4 ? ~0ull
                                                                                                           : (a & 0xFF00FF0000FFFF00ull);
      positive[w] = rng();
    }
    size_t count = 0;
    for (uint64_t w : active) count += size_t(__builtin_popcountll(w));
    const uint32_t m = uint32_t(rng()) | (trial % 2 ? 0x80000000u : 0u);
    char* stream = pages + 2 * page - long(4 * count);
    for (size_t i = 0; i < count; ++i) {
      const uint32_t x = uint32_t(rng());
      std::memcpy(stream + 4 * i, &x, 4);
    }
    std::vector<uint32_t> stream32(count);
    if (count) std::memcpy(stream32.data(), stream, 4 * count);  // an empty vector's data() may be null (UBSan)
    const std::vector<uint32_t> want = reference(active, positive, m, stream32.data());
    for (LeafExpansion how : leafExpansions()) {
      std::vector<float> got(512, 1.0f);
      const char* end = expandCompactLeafWith(how, got.data(), active, positive, m, stream);
      ASSERT_EQ(end, stream + 4 * count) << int(how);
      ASSERT_EQ(std::memcmp(got.data(), want.data(), 512 * 4), 0) << "way " << int(how) << ", trial " << trial;
    }
  }
  munmap(pages, size_t(3 * page));
}

// countVoxels against a count bit by bit: empty, full, single bits at every place, random masks.
TEST(LeafExpand, CountVoxelsCountsEveryBitOfTheMask) {
  auto byBits = [](const uint64_t m[8]) {
    size_t n = 0;
    for (int i = 0; i < 512; ++i) n += (m[i >> 6] >> (i & 63)) & 1;
    return n;
  };
  uint64_t mask[8] = {};
  EXPECT_EQ(countVoxels(mask), 0u);
  for (int i = 0; i < 512; ++i) {
    std::memset(mask, 0, sizeof mask);
    mask[i >> 6] = uint64_t(1) << (i & 63);
    ASSERT_EQ(countVoxels(mask), 1u) << i;
  }
  std::memset(mask, 0xFF, sizeof mask);
  EXPECT_EQ(countVoxels(mask), 512u);
  std::mt19937_64 rng(17);
  for (int r = 0; r < 1000; ++r) {
    for (uint64_t& w : mask) w = rng() & rng();
    ASSERT_EQ(countVoxels(mask), byBits(mask)) << r;
  }
}
