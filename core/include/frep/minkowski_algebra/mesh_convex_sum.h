// Minkowski sum and difference of a closed triangle mesh and a convex polytope, exactly and
// without a search (issue 30: mesh ⊕ box, mesh ⊕ tetrahedral tool, tetrahedron ⊕ box, ...).
//
// The sum (Roerdink-Minkowski eq. 1, A ⊕ B = { a + b }) of a solid A and a connected B splits
// into the translate of A and the sweep of its boundary: for any b0 in B,
//
//   A ⊕ B = (A + b0)  ∪  ⋃_T (T ⊕ B),   T the triangles of ∂A,
//
// because x ∈ A ⊕ B iff the connected set x − B meets A, and then either lies inside A (so
// x − b0 ∈ A) or crosses ∂A. Each T ⊕ B is a convex polytope whose facet normals are among T's
// normal ±n_T, B's facet normals and the cross products of T's edges with B's edges (the faces
// of a sum of polytopes are sums of faces with a common normal), so
//
//   c_T(x) = min_u ( h_T(u) + h_B(u) − u · x ),   h the support functions,
//
// over those candidate unit normals u is T ⊕ B's exact inside distance (a redundant supporting
// plane is never nearer than a facet). The field is
//
//   g(x) = max( f_A(x − b0), max_T c_T(x) ),        f = g where g >= 0, else −dist(x, S),
//
// with S the boundary pieces of every T ⊕ B (vertex of T + facet of B, edge ⊕ edge
// parallelograms, T + vertex of B), a triangle soup inside A ⊕ B that covers its boundary, so
// dist(x, S) is the exact distance outside. f is sign-exact, the exact signed distance outside,
// a lower bound of the depth inside, and 1-Lipschitz (each piece is).
//
// The difference with frMinkowskiDiff's convention, A ⊖ B = { x : x + B ⊆ A }, is the
// complement of A^c ⊕ (−B): the same construction on the flipped mesh, negated (exact inside).
//
// B may also be flat: a segment [p, q], support h_B(u) = max(u · p, u · q), no facets, one edge
// direction d. Then T ⊕ B is the prism of T along d (facet normals ±n_T and the edges' e × d),
// or, when d lies in T's plane, the flat polygon of T at both ends, bounded within the plane by
// the in-plane normals n_T × e and n_T × d. A path P = p_0 ... p_k is the connected union of such
// segments, so a sweep by translation A ⊕ P = ∪_t (A + p(t)) is the same construction.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::minkowski {

// A ⊕ B over x[0..3) when one operand is a closed triangle mesh (or a convex polytope, whose
// boundary mesh is used) and the other a convex polytope: an intersection of half-spaces
// (convex_polytope.h) or a closed convex mesh of at most 4096 triangles. Registers the result.
bool meshConvexSum(const Expr& a, const Expr& b, uint32_t dims, Expr* out);
// The metamorphosis (1 - t) A ⊕ t B (Pasko-Minkowski eq. 4.5, scalings about the origin) of such
// operands, 0 < t < 1.
bool meshConvexMorph(const Expr& a, const Expr& b, double t, Expr* out);
// A ⊖ B when A is a closed mesh (or a polytope) and B a convex polytope.
bool meshConvexDifference(const Expr& a, const Expr& b, uint32_t dims, Expr* out);
// A ⊕ P, the sweep of a closed mesh A (or a polytope) by translation along the polyline P through
// path (at least one point, at most 64 segments): path_sweep.h's form for meshes. Registers the
// result ("sweep of bunny.stl (3674 triangles) along a path of 4 points (3 segments) ...").
bool meshPathSum(const Expr& a, const std::vector<std::array<double, 3>>& path, Expr* out);

}  // namespace frep::minkowski
