// Sweeps by translation along a polyline, exactly and without a search (issue 30: sweeps get
// the treatment of sums). A moved by p(t), piecewise linear through p_0, ..., p_k, covers
//
//   ∪_t (A + p(t)) = A ⊕ P = ∪_i A ⊕ [p_i, p_{i+1}],   P the polyline   (Roerdink eq. 1)
//
// For a ball (c, r), A ⊕ [p, q] is the capsule { X : dist(X − c, [p, q]) ≤ r }, whose field
// r − dist is exact; for a convex polytope K it is the convex hull of K + p and K + q (a sum of
// convex sets is convex, and its vertices are sums of vertices), a closed mesh with an exact
// signed distance; a union of polytopes (convex_polytope.h) sweeps piece by piece. The field
// is the max over the pieces: sign-exact, the exact signed distance outside the sweep, a lower
// bound of the depth inside. A closed triangle mesh (an frMesh part, a non-convex tool) sweeps
// as the sum of the mesh and the path (mesh_convex_sum.h with segments for B): its translate
// united with the prisms T ⊕ [p_i, p_{i+1}] of its triangles, the same guarantees.
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

// The sweep of a over x[0..3) along path (at least one point), when a is a ball (frBall,
// hfSphere), a convex polytope or a union of polytopes, with at most 256 pieces (segments x
// the operand's pieces), or a closed mesh with at most 64 segments. Registers the result
// ("exact Minkowski sum sweep of ...").
bool translationSweep(const Expr& a, const std::vector<Vec3>& path, Expr* out);
// The same with the path given as keyframe positions x, y, z one after the other (frSweepKeys),
// when they are constants.
bool keyframeSweep(const Expr& a, const std::vector<Expr>& positions, Expr* out);

}  // namespace frep::minkowski
