// Shared by the mesh ⊕ convex polytope tests (mesh_convex_sum_test.cpp, the construction and
// its closed forms; mesh_convex_sum_classes_test.cpp, the classes, bounds and sign-only paths):
// coordinates, point values, boxes as six planes and their exact distance, the L prism's sum.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/primitives/ops.h"

namespace frep::mesh_convex_sum_shapes {

using V3 = std::array<double, 3>;
inline Expr X() { return Expr::x(0); }
inline Expr Y() { return Expr::x(1); }
inline Expr Z() { return Expr::x(2); }

inline double eval(const Expr& e, const V3& p) {
  TapePtr t = Tape::compile(e, 3);
  PointEvaluator pe;
  return pe.eval(*t, p.data());
}

inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// The box corner + sum_i t_i g_i (t in [0, 1]^3) written as six planes (a min of affine
// functions, recognised as a convex polytope).
inline Expr parallelepiped(const V3& corner, const std::array<V3, 3>& g) {
  Expr f;
  bool first = true;
  for (int i = 0; i < 3; ++i) {
    V3 n = cross(g[size_t((i + 1) % 3)], g[size_t((i + 2) % 3)]);
    if (dot(n, g[size_t(i)]) < 0) n = {-n[0], -n[1], -n[2]};
    const double l = std::sqrt(dot(n, n));
    for (double& c : n) c /= l;
    const double lo = dot(n, corner), hi = lo + dot(n, g[size_t(i)]);
    const Expr s = n[0] * X() + n[1] * Y() + n[2] * Z();
    const Expr slab = min(s - lo, hi - s);
    f = first ? slab : min(f, slab);
    first = false;
  }
  return f;
}

inline Expr axisBox(const V3& lo, const V3& hi) {
  return parallelepiped(lo, {V3{hi[0] - lo[0], 0, 0}, V3{0, hi[1] - lo[1], 0}, V3{0, 0, hi[2] - lo[2]}});
}

// The exact signed distance of the axis box [lo, hi] (positive inside).
inline double boxDistance(const V3& p, const V3& lo, const V3& hi) {
  double out = 0, in = -INFINITY;
  for (int i = 0; i < 3; ++i) {
    const double c = 0.5 * (lo[size_t(i)] + hi[size_t(i)]), h = 0.5 * (hi[size_t(i)] - lo[size_t(i)]);
    const double q = std::abs(p[size_t(i)] - c) - h;
    out += q > 0 ? q * q : 0;
    in = std::max(in, q);
  }
  return out > 0 ? -std::sqrt(out) : -in;
}

// L ⊕ C and L ⊖ C for the L prism of height 0.4 and a small box C (the tests of classes,
// bounds and sign-only sampling).
inline bool lPrismSumAndDifference(Expr& sum, Expr& diff) {
  const V3 clo{-0.1, -0.2, -0.15}, chi{0.3, 0.05, 0.1};
  return minkowski::meshConvexSum(axisBox(clo, chi), mesh_models::lPrismMesh(0.4), 3, &sum) &&
         minkowski::meshConvexDifference(mesh_models::lPrismMesh(0.4), axisBox(clo, chi), 3, &diff);
}

}  // namespace frep::mesh_convex_sum_shapes
