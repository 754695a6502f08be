// Per-thread lists of candidates for the cells of a lattice, built the first time a query
// reaches a cell (mesh_field.cpp: the triangles that can be nearest; mesh_convex_sum.cpp: the
// pieces whose boxes meet the cell). Queries come in nearby runs, so a cell's list serves many.
// Per thread: no locks, and an answer must never depend on which lists exist (each user makes
// its lists supersets of what any point of the cell needs).
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace frep {

// A cubic lattice: cell (i, j, k) is [origin + (i, j, k) size, origin + (i + 1, j + 1, k + 1) size)
// up to rounding (a point may be placed in a neighbour within a few ulps: users give their
// lists that much slack).
struct CellLattice {
  double origin[3] = {0, 0, 0};
  double size = 1, inverse = 1;  // inverse = 1 / size
  // The lattice over a box [lo, hi]: `cells` along its longest side, `margin` cells around it.
  static CellLattice over(const double lo[3], const double hi[3], int cells, int margin);
  // The key of the cell holding p and its indices; false outside 2^20 cells a side.
  bool cellOf(const double* p, uint64_t& key, int64_t ijk[3]) const;
  void cellBox(const int64_t ijk[3], double lo[3], double hi[3]) const;
};

class CellLists {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;  // a cell given no list
  // A key for a new owner (a field): the lists of different owners never mix.
  static uint64_t newOwner();
  // The list of the cell of `lattice` holding p, built by build(lo, hi, out) from the cell's
  // box; nullptr also when p is outside the lattice.
  template <typename Build>
  static const uint32_t* at(uint64_t owner, const CellLattice& lattice, const double* p, uint32_t& count,
                            Build&& build) {
    uint64_t key;
    int64_t ijk[3];
    if (!lattice.cellOf(p, key, ijk)) return nullptr;
    return get(owner, key, count, [&](std::vector<uint32_t>& out) {
      double lo[3], hi[3];
      lattice.cellBox(ijk, lo, hi);
      return build(lo, hi, out);
    });
  }
  // The list of `key` for `owner` on this thread, built by build(out) (appending to out and
  // returning false for "no list") the first time; nullptr when the cell has no list.
  template <typename Build>
  static const uint32_t* get(uint64_t owner, uint64_t key, uint32_t& count, Build&& build) {
    Lists& l = listsOf(owner);
    if (!(l.hasLast && l.lastKey == key)) {  // runs of queries stay in one cell
      auto it = l.cells.find(key);
      if (it == l.cells.end()) {
        if (l.items.size() > kMaxItems) l.cells.clear(), l.items.clear();
        const uint32_t first = uint32_t(l.items.size());
        const bool has = build(l.items);
        if (!has) l.items.resize(first);
        it = l.cells.emplace(key, std::make_pair(first, has ? uint32_t(l.items.size() - first) : kNone)).first;
      }
      l.hasLast = true, l.lastKey = key, l.last = it->second;
    }
    if (l.last.second == kNone) return nullptr;
    count = l.last.second;
    return l.items.data() + l.last.first;
  }

 private:
  static constexpr size_t kMaxItems = size_t(1) << 23;  // 32 MB a thread and owner, then cleared
  struct Lists {
    uint64_t owner = 0;
    std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> cells;  // key -> (first, count)
    std::vector<uint32_t> items;
    bool hasLast = false;  // the last cell asked for
    uint64_t lastKey = 0;
    std::pair<uint32_t, uint32_t> last;
  };
  static Lists& listsOf(uint64_t owner);
};

}  // namespace frep
