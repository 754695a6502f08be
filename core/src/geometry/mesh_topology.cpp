// Welding and edge uses of a triangle mesh (mesh_topology.h).
#include "geometry/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "meshing/radix_sort.h"

namespace frep::mesh_topology {

std::vector<uint32_t> weldVertices(const std::vector<double>& xyz, std::vector<double>& welded) {
  const size_t nv = xyz.size() / 3;
  for (double c : xyz)
    if (!std::isfinite(c)) throw std::invalid_argument("a vertex coordinate is not a finite number");
  size_t slots = 16;
  while (slots < 2 * nv) slots *= 2;
  std::vector<uint32_t> table(slots, UINT32_MAX);  // welded vertex numbers, open addressing
  std::vector<uint32_t> remap(nv);
  for (size_t i = 0; i < nv; ++i) {
    const double* p = &xyz[3 * i];
    uint64_t h = 0x9E3779B97F4A7C15ULL;
    for (int k = 0; k < 3; ++k) {
      const double c = p[k] + 0.0;  // -0 hashes as 0, as they compare equal
      uint64_t bits;
      std::memcpy(&bits, &c, sizeof bits);
      h = (h ^ bits) * 0xff51afd7ed558ccdULL;
      h ^= h >> 32;
    }
    for (size_t s = h & (slots - 1);; s = (s + 1) & (slots - 1)) {
      const uint32_t id = table[s];
      if (id == UINT32_MAX) {
        table[s] = remap[i] = uint32_t(welded.size() / 3);
        welded.insert(welded.end(), p, p + 3);
        break;
      }
      const double* q = &welded[3 * size_t(id)];
      if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) {
        remap[i] = id;
        break;
      }
    }
  }
  return remap;
}

EdgeUses edgeUsesOf(const std::vector<uint32_t>& tris) {
  struct Use {
    uint64_t key;
    uint32_t use;
  };
  std::vector<Use> uses(tris.size());
  for (size_t t = 0; t + 2 < tris.size(); t += 3)
    for (size_t c = 0; c < 3; ++c) uses[t + c] = {edgeKey(tris[t + c], tris[t + (c + 1) % 3]), uint32_t(t + c)};
  radixSortByKey(uses, [](const Use& u) { return u.key; });  // stable: equal keys stay in use order
  EdgeUses out;
  out.key.resize(uses.size());
  out.use.resize(uses.size());
  for (size_t i = 0; i < uses.size(); ++i) out.key[i] = uses[i].key, out.use[i] = uses[i].use;
  return out;
}

}  // namespace frep::mesh_topology
