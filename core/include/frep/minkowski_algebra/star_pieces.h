// A closed star-shaped mesh as a union of convex pieces, so that a sum with a non-convex tool
// runs on the exact mesh ⊕ polytope construction (mesh_convex_sum.h; issue 30). With c a point
// of the kernel (every face's plane has c strictly on its inner side), the mesh's solid is the
// union of the pyramids from c over its faces; coplanar neighbouring triangles are merged while
// their union stays a convex polygon, so a box-like tool gives one pyramid per face, and the
// pyramids are convex (c is inside each base's half-space). By Roerdink-Minkowski eq. 1,
// A ⊕ ∪_i P_i = ∪_i (A ⊕ P_i). The fallback of convex_cover.h (fewer, fuller pieces).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "frep/geometry/vec3.h"

namespace frep::minkowski {

// One convex piece as a closed, outward-oriented triangle mesh.
struct PieceMesh {
  std::vector<Vec3> v;
  std::vector<std::array<uint32_t, 3>> t;
};

// The pieces of the closed, outward-oriented mesh (v, t), or nothing when no kernel point with
// a margin of tol is found (the mesh is not star-shaped, or only barely) or more than maxPieces
// would be needed. The search for c tries the vertex centroid and points just inside faces,
// then climbs the least margin (a subgradient ascent): it may miss a thin kernel, never
// accepts a point outside it.
std::optional<std::vector<PieceMesh>> starConvexPieces(const std::vector<Vec3>& v,
                                                       const std::vector<std::array<uint32_t, 3>>& t, double tol,
                                                       size_t maxPieces);

}  // namespace frep::minkowski
