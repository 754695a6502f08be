// radixSortByKey (core/src/meshing/radix_sort.h), the mesher's sort of edge records: the same
// order as std::stable_sort by the key, below and above its small-input cut-off, for keys that
// share bytes (skipped passes), differ in every byte, or repeat.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "meshing/radix_sort.h"

using frep::radixSortByKey;

TEST(RadixSort, EqualsStableSortByKey) {
  std::mt19937_64 rng(3);
  const uint64_t masks[] = {~0ull, 0xff00ff00ull, 0x0000ffff00000000ull, 0x7ull};
  for (size_t n : {0u, 1u, 2u, 100u, 511u, 512u, 4097u, 100000u})
    for (uint64_t mask : masks) {
      std::vector<std::pair<uint64_t, uint32_t>> v(n);  // (key, original position)
      for (size_t i = 0; i < n; ++i) v[i] = {(rng() & mask) | 0x0123000000000000ull, uint32_t(i)};
      auto expected = v;
      std::stable_sort(expected.begin(), expected.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      radixSortByKey(v, [](const std::pair<uint64_t, uint32_t>& x) { return x.first; });
      ASSERT_EQ(v, expected) << "n " << n << " mask " << std::hex << mask;
    }
}
