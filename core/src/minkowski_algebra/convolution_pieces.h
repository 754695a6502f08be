// The boundary pieces of the sums of mesh_convex_sum.h: the convolution of a closed mesh's
// boundary with a convex piece's, a triangle soup inside A ⊕ B that covers its boundary.
#pragma once

#include <functional>
#include <vector>

#include "mesh_operands.h"

namespace frep::minkowski::mesh_operands {

using EmitTriangle = std::function<void(const V3&, const V3&, const V3&)>;

// The pieces a + b of ∂A ⊕ ∂B with a common outward normal u (the convolution of the two
// boundaries), which cover the boundary of A ⊕ B: a boundary point x = a + b has x − B outside
// A touching it at a, so b ∈ F_B(u) for an outward normal u of A at a. On a face's interior u is
// its normal: T + F_B(n_T). On a convex edge u runs over the arc between its faces' normals: the
// parallelograms e ⊕ e_B of the B edges whose normal arcs meet it. A reflex edge or vertex adds
// nothing (x − B lies in the convex outer wedge, so b ∈ F_B of each incident face: the face pieces
// hold x). A convex vertex: v + the B facets whose normals lie in its normal cone; a saddle
// vertex: v + every B facet (a superset, as every piece lies in A ⊕ B).
//
// B may be a segment [p, q] (a piece of a path, path_sweep.h), direction d: it has no facets, so
// vertices add nothing. A face T gives T + p, T + q, or where d ⊥ n_T the flat hull of both; an
// edge the parallelogram e ⊕ [p, q] where its normal arc crosses d's normal plane. The vertex
// points v + p are on face pieces: x − B leaves v along −d outside A, so −d is not in the
// kernel of A's tangent cone at v (the intersection of the incident faces' inner half-spaces,
// which lies in the cone), so some incident face has n_T · d <= 0 and p ∈ F_B(n_T). Where x − B
// passes through v, n_T · d changes sign around v at a convex edge (at a reflex one the segment
// would enter A), whose parallelogram holds x, or vanishes on a face, whose flat hull does.
// bDirs: B's edge directions, one per parallel class; complement: the pieces of A^c ⊕ B; tol:
// the tolerance of the support faces and the edge tests.
void convolutionPieces(const Mesh& a, const Convex& b, const std::vector<V3>& bDirs, bool complement, double tol,
                       const EmitTriangle& tri);

}  // namespace frep::minkowski::mesh_operands
