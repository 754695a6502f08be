#include "frep/master/leaf_order.h"

#include <stdexcept>
#include <tbb/parallel_sort.h>

namespace frep::farm {

void rankByOrigin(const std::vector<std::array<int32_t, 3>>& origins, const std::array<int32_t, 3>& lo,
                  const std::array<int32_t, 3>& hi, std::vector<size_t>& rank, size_t maxCellsPerLeaf) {
  size_t cells[3];
  for (int a = 0; a < 3; ++a) cells[a] = hi[a] > lo[a] ? size_t((int64_t(hi[a]) - lo[a] + 7) / 8) : 0;
  auto cellOf = [&](const std::array<int32_t, 3>& o) {
    size_t c = 0;
    for (int a = 0; a < 3; ++a) {
      const int64_t d = int64_t(o[size_t(a)]) - lo[size_t(a)];
      if (d < 0 || d % 8 != 0 || size_t(d / 8) >= cells[a]) throw std::logic_error("a kept leaf lies outside its slab");
      c = c * cells[a] + size_t(d / 8);
    }
    return c;
  };
  rank.resize(origins.size());
  const double grid = double(cells[0]) * double(cells[1]) * double(cells[2]);
  if (grid <= double(maxCellsPerLeaf) * double(origins.size())) {
    // Counting sort: each cell's first rank is the count of origins in the cells before it.
    std::vector<size_t> next(size_t(grid) + 1, 0);
    for (const auto& o : origins) ++next[cellOf(o) + 1];
    for (size_t c = 1; c < next.size(); ++c) next[c] += next[c - 1];
    for (size_t i = 0; i < origins.size(); ++i) rank[i] = next[cellOf(origins[i])]++;
    return;
  }
  for (const auto& o : origins) cellOf(o);  // the same check
  std::vector<size_t> order(origins.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  tbb::parallel_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return origins[a] < origins[b] || (origins[a] == origins[b] && a < b);
  });
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = r;
}

}  // namespace frep::farm
