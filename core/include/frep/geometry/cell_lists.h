// Per-thread lists of candidates for the cells of a lattice, built the first time a query
// reaches a cell (mesh_field.cpp: the triangles that can be nearest; mesh_convex_sum.cpp: the
// pieces whose boxes meet the cell). Queries come in nearby runs, so a cell's list serves many.
// Per thread: no locks, and an answer must never depend on which lists exist (each user makes
// its lists supersets of what any point of the cell needs).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstring>
#include <cstdint>
#include <utility>
#include <vector>

namespace frep {

// The lists keep bounds as float bits: x rounded down to a float (a lower bound stays one,
// whatever its sign), and the bits of a float and back.
inline float floatBelow(double x) {
  const float f = float(x);
  return double(f) > x ? std::nextafter(f, -INFINITY) : f;
}
inline uint32_t bitsOfFloat(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}
inline float floatOfBits(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// A cubic lattice: cell (i, j, k) is [origin + (i, j, k) size, origin + (i + 1, j + 1, k + 1) size)
// up to rounding (a point may be placed in a neighbour within a few ulps: users give their
// lists that much slack).
struct CellLattice {
  double origin[3] = {0, 0, 0};
  double size = 1, inverse = 1;  // inverse = 1 / size
  // The lattice over a box [lo, hi]: `cells` along its longest side, `margin` cells around it.
  static CellLattice over(const double lo[3], const double hi[3], int cells, int margin);
  // The key of the cell holding p and its indices; false outside 2^20 cells a side. Inline and
  // without std::floor (a libm call on baseline x86-64): a class query asks this up to three
  // times. For u >= 0, truncation is the floor; u < 0 or NaN fails the test either way.
  bool cellOf(const double* p, uint64_t& key, int64_t ijk[3]) const {
    for (int k = 0; k < 3; ++k) {
      const double u = (p[k] - origin[k]) * inverse;
      if (!(u >= 0 && u < double(1 << 20))) return false;
      ijk[k] = int64_t(u);
    }
    key = uint64_t(ijk[0]) | uint64_t(ijk[1]) << 20 | uint64_t(ijk[2]) << 40;
    return true;
  }
  void cellBox(const int64_t ijk[3], double lo[3], double hi[3]) const {
    for (int k = 0; k < 3; ++k) {
      lo[k] = origin[k] + double(ijk[k]) * size;
      hi[k] = origin[k] + double(ijk[k] + 1) * size;
    }
  }
};

class CellLists {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;         // a cell given no list
  static constexpr uint32_t kPending = UINT32_MAX - 1;  // a cell seen once: no list yet
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
  // returning false for "no list") the second time a query reaches the cell; nullptr when the
  // cell has no list, or none yet. A list costs a few queries without one: a cell that sees
  // one query only (a coarse grid, a pass over scattered points) is not worth it (building at
  // the first query instead made bunny (+) tetrahedron 6% slower).
  template <typename Build>
  static const uint32_t* get(uint64_t owner, uint64_t key, uint32_t& count, Build&& build) {
    Lists& l = listsOf(owner);
    Slot& hit = l.recent[Lists::recentOf(key)];
    if (hit.key != key) {
      Slot* slot = l.find(key);
      if (slot->key != key) {
        *slot = {key, 0, kPending};
        if (++l.used * 2 > l.slots.size()) slot = l.grow(key);
      } else if (slot->count == kPending) {
        if (l.items.size() > kMaxItems) {
          l.clear(), slot = l.find(key);
          ++l.used;
        }
        const uint32_t first = uint32_t(l.items.size());
        const bool has = build(l.items);
        if (!has) l.items.resize(first);
        *slot = {key, first, has ? uint32_t(l.items.size() - first) : kNone};
      }
      if (slot->count == kPending) return nullptr;
      hit = *slot;
    }
    if (hit.count == kNone) return nullptr;
    count = hit.count;
    return l.items.data() + hit.first;
  }

 private:
  static constexpr size_t kMaxItems = size_t(1) << 23;  // 32 MB a thread and owner, then cleared
  static constexpr uint64_t kEmpty = UINT64_MAX;        // no lattice key is (keys have 60 bits)
  // An open-addressing table of the cells' (first, count) in `items`: one probe of a flat array
  // where a node-based map chased three pointers (a fifth of the sum's class queries went there).
  struct Slot {
    uint64_t key;
    uint32_t first, count;
  };
  struct Lists {
    uint64_t owner = 0;
    std::vector<Slot> slots;  // a power of two, at most half used
    size_t used = 0;
    std::vector<uint32_t> items;
    // The cells asked for last whose lists are settled (built, or none), direct-mapped: the
    // table grows to megabytes, and queries come in runs over a few cells (a collapse's error
    // samples straddle the surface: seven in eight queries of bunny (+) tetrahedron hit).
    Slot recent[64];
    static size_t recentOf(uint64_t key) { return size_t((key * 0x9E3779B97F4A7C15ULL) >> 58); }
    // The slot holding key, or the empty slot where it goes.
    Slot* find(uint64_t key) {
      const size_t mask = slots.size() - 1;
      for (size_t i = (key * 0x9E3779B97F4A7C15ULL) >> 32 & mask;; i = (i + 1) & mask)
        if (slots[i].key == key || slots[i].key == kEmpty) return &slots[i];
    }
    Slot* grow(uint64_t key);
    void clear();
  };
  static Lists& listsOf(uint64_t owner);
};

}  // namespace frep
