// Internal to core: the marching-tetrahedra rules shared by the model mesher (mesh.cpp, which
// builds the tables) and the sampled-values mesher (mesh_grid.cpp), so both mesh a cell the same
// way by construction (docs/mesh.md).
//
// A cell is split into the six Kuhn tetrahedra around its main diagonal: tetrahedron t is
// 0 -> e_a -> e_a + e_b -> (1,1,1) for the t-th permutation (a, b, c) of the axes, in the order
// (0,1,2), (0,2,1), (1,0,2), (1,2,0), (2,0,1), (2,1,0). A cell corner is a 3-bit mask (bit a: +1
// along axis a). Every edge of a tetrahedron joins two corners one of which contains the other;
// it is given as its smaller corner (lo) and the steps to the larger one (dir, 1..7).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace frep {

// One oriented polygon (a triangle or a quad) of one tetrahedron: its corners are the crossings
// of `count` edges, wound so that its normal, taken on the edges' midpoints, points from the
// inside corners towards the outside ones.
struct KuhnPolygon {
  uint8_t count;  // 3 or 4
  uint8_t lo[4], dir[4];
};

// The polygons of a cell: at most one per tetrahedron, in tetrahedron order.
struct KuhnCell {
  int count;  // 0..6
  KuhnPolygon polygons[6];
};

// The polygons of a cell whose inside corners are the set bits of insideMask (bit c: corner c,
// c = 0..7); no polygon for 0 and 255.
const KuhnCell& kuhnCell(unsigned insideMask);

// Calls polygon(keys, count) for each polygon of the cell at (x, y, z) with that inside mask, its
// corners given as the global keys of their edges (mesh.h), and edge(key, loInside) for each
// of those corners (the edge and whether its smaller-corner end is inside).
template <typename EdgeKeyFn, typename EdgeFn, typename PolygonFn>
void forCellPolygons(unsigned mask, int64_t x, int64_t y, int64_t z, EdgeKeyFn&& edgeKeyOf, EdgeFn&& edge,
                     PolygonFn&& polygon) {
  const KuhnCell& cell = kuhnCell(mask);
  for (int p = 0; p < cell.count; ++p) {
    const KuhnPolygon& poly = cell.polygons[p];
    uint64_t keys[4];
    for (int q = 0; q < poly.count; ++q) {
      const uint8_t lo = poly.lo[q];
      keys[q] = edgeKeyOf(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), poly.dir[q]);
      edge(keys[q], bool((mask >> lo) & 1));
    }
    polygon(keys, poly.count);
  }
}

// Appends the two triangles of quad q (corners p), split along its shorter diagonal (ties: 0-2),
// a choice made from the quad alone; both keep the quad's winding.
template <typename V>
void splitKuhnQuad(const std::array<V, 4>& q, const std::array<double, 3>* const p[4],
                   std::vector<std::array<V, 3>>& tris) {
  auto dist2 = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    double s = 0;
    for (int c = 0; c < 3; ++c) s += (a[c] - b[c]) * (a[c] - b[c]);
    return s;
  };
  if (dist2(*p[0], *p[2]) <= dist2(*p[1], *p[3])) {
    tris.push_back({q[0], q[1], q[2]});
    tris.push_back({q[0], q[2], q[3]});
  } else {
    tris.push_back({q[1], q[2], q[3]});
    tris.push_back({q[1], q[3], q[0]});
  }
}

}  // namespace frep
