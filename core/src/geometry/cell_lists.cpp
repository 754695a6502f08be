// Per-thread candidate lists of lattice cells (cell_lists.h).
#include "frep/geometry/cell_lists.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace frep {

CellLattice CellLattice::over(const double lo[3], const double hi[3], int cells, int margin) {
  CellLattice l;
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  l.size = extent / cells;
  l.inverse = 1 / l.size;
  for (int k = 0; k < 3; ++k) l.origin[k] = lo[k] - margin * l.size;
  return l;
}

uint64_t CellLists::newOwner() {
  static std::atomic<uint64_t> next{1};
  return next++;
}

// A few owners a thread (a model may hold several meshes), replaced round robin.
CellLists::Lists& CellLists::listsOf(uint64_t owner) {
  constexpr int kOwners = 4;
  thread_local Lists lists[kOwners];
  thread_local int next = 0;
  for (Lists& l : lists)
    if (l.owner == owner) return l;
  Lists& l = lists[next];
  next = (next + 1) % kOwners;
  l.owner = owner;
  l.clear();
  return l;
}

void CellLists::Lists::clear() {
  slots.assign(1024, Slot{kEmpty, 0, 0});
  used = 0;
  items.clear();
  for (Slot& r : recent) r = Slot{kEmpty, 0, kNone};
}

// Twice the slots, every key placed again; the new slot of key.
CellLists::Slot* CellLists::Lists::grow(uint64_t key) {
  std::vector<Slot> old(slots.size() * 2, Slot{kEmpty, 0, 0});
  old.swap(slots);
  for (const Slot& s : old)
    if (s.key != kEmpty) *find(s.key) = s;
  return find(key);
}

}  // namespace frep
