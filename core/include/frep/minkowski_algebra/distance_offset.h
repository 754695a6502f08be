// Minkowski sum and difference of an exact signed-distance operand and a ball, without a
// search. If f_A is the exact Euclidean signed distance to A outside A (f_A = -dist(., A)),
//
//   A ⊕ ball(c, r) = { x : dist(x - c, A) <= r } = { f_A(x - c) + r >= 0 },
//
// and if it is exact inside (f_A = dist(., complement of A)), with frMinkowskiDiff's convention
// A ⊖ B = { x : x + B ⊆ A },
//
//   A ⊖ ball(c, r) = { x : ball(x + c, r) ⊆ A } = { f_A(x + c) - r >= 0 }.
//
// Operands that qualify: a DistanceField node (geometry/field.h) whose exactOutside() /
// exactInside() says so, read at translated coordinates (x_i or x_i ± constant), and earlier
// results of this path: a sum's f_A + r is again exact outside, a difference's f_A - r exact
// inside (the distance to the offset set changes by exactly r along the nearest-point segment),
// so chains of balls stay on the path. The ball is a registered basic-set sum of spheres
// (frBall; registry.h). Anything else (a sampled .vdb volume, an open mesh, a formula): false,
// and the caller searches.
#pragma once

#include <cstdint>
#include <optional>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

struct Ball {
  Vec3 centre{0, 0, 0};
  double radius = 0;
  Sum sum;
};

// A registered basic-set sum with no block edges and no discs (frBall, hfSphere): a ball
// (radius 0: a point).
std::optional<Ball> ballOf(const Expr& e);

// A ⊕ B over x[0..3) when one operand is a ball and the other exact outside; registers the
// result (describeExact: "exact Minkowski sum ..., error bound 0").
bool distanceBallSum(const Expr& a, const Expr& b, uint32_t dims, Expr* out);
// A ⊖ B when B is a ball and A exact inside.
bool distanceBallDifference(const Expr& a, const Expr& b, uint32_t dims, Expr* out);

}  // namespace frep::minkowski
