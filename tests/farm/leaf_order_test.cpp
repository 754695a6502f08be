// rankByOrigin (master/leaf_order.h), where the master's merge puts each leaf: both of its sorts
// (counting over the slab's cells, comparison) give the ranks of a stable sort by origin.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

#include "frep/master/leaf_order.h"

using frep::farm::rankByOrigin;
using Origin = std::array<int32_t, 3>;

namespace {
std::vector<size_t> stableRanks(const std::vector<Origin>& origins) {
  std::vector<size_t> order(origins.size()), rank(origins.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return origins[a] < origins[b]; });
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = r;
  return rank;
}
}  // namespace

TEST(LeafOrder, CountingAndComparisonSortsGiveTheStableSortsRanks) {
  std::mt19937 rng(3);
  const Origin lo{64, -32, 8}, hi{128, 40, 100};  // a slab: 8 x 9 x 12 cells of 8^3 (the last one partial)
  for (size_t n : {size_t(0), size_t(1), size_t(5), size_t(60), size_t(400), size_t(3000)}) {
    std::vector<Origin> origins(n);
    for (Origin& o : origins)  // repeats included (a worker may send one origin twice)
      o = {lo[0] + 8 * int32_t(rng() % 8), lo[1] + 8 * int32_t(rng() % 9), lo[2] + 8 * int32_t(rng() % 12)};
    const std::vector<size_t> want = stableRanks(origins);
    std::vector<size_t> counting, comparison;
    rankByOrigin(origins, lo, hi, counting, size_t(1) << 40);  // always counts
    rankByOrigin(origins, lo, hi, comparison, 0);              // always compares
    EXPECT_EQ(counting, want) << n;
    EXPECT_EQ(comparison, want) << n;
  }
}

TEST(LeafOrder, AnOriginOutsideTheSlabOrOffItsGridIsRefused) {
  const Origin lo{0, 0, 0}, hi{64, 64, 64};
  std::vector<size_t> rank;
  for (size_t cellsPerLeaf : {size_t(1) << 40, size_t(0)})
    for (const Origin& bad : {Origin{64, 0, 0}, Origin{0, -8, 0}, Origin{0, 0, 4}, Origin{0, 0, 1 << 30}}) {
      std::vector<Origin> origins{{0, 0, 0}, bad};
      EXPECT_THROW(rankByOrigin(origins, lo, hi, rank, cellsPerLeaf), std::logic_error);
    }
}
