// Internal to core: the topology a triangle mesh field is built on (mesh_field.cpp), in sorts
// and one flat hash table rather than node-based maps (a 640,000-triangle STL spent most of
// its load in std::map welding and edge lookups).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frep::mesh_topology {

// Equal coordinates (by ==, so -0 is 0) become one vertex, numbered in order of first
// appearance, with the first appearance's coordinates appended to `welded`. Returns each input
// vertex's number. Throws std::invalid_argument for a coordinate that is not finite.
std::vector<uint32_t> weldVertices(const std::vector<double>& xyz, std::vector<double>& welded);

// The undirected edges of triangles (3 vertex numbers each): every use 3 t + c (triangle t's
// edge from corner c to corner c + 1) keyed by its two vertices (smaller in the high half),
// sorted by key and, among equal keys, by use.
struct EdgeUses {
  std::vector<uint64_t> key;
  std::vector<uint32_t> use;
  // Calls f(first, last) for each edge: its uses are [first, last) of the arrays.
  template <typename F>
  void forEachEdge(F&& f) const {
    for (size_t i = 0, j; i < key.size(); i = j) {
      for (j = i + 1; j < key.size() && key[j] == key[i];) ++j;
      f(i, j);
    }
  }
};
inline uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a; }
EdgeUses edgeUsesOf(const std::vector<uint32_t>& tris);

}  // namespace frep::mesh_topology
