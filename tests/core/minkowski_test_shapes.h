// Shared by the Minkowski algebra tests: members built by kind, independent F-reps of single
// members (written without the reduction code), a reduction's world box and its lattice volume.
#pragma once

#include <cmath>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/reduction.h"

namespace frep::minkowski::test_shapes {

constexpr double kPi = 3.14159265358979323846;

inline Shape member(ShapeKind k, int axis, double size, Mat3 rot = identityRotation()) {
  Shape s;
  s.kind = k;
  s.axis = axis;
  s.size[0] = size;
  s.rot = rot;
  return s;
}

// Minus the distance for segments and discs, r − |X − c| for spheres (world coordinates).
inline Expr memberExpr(const Shape& s) {
  Expr q[3];
  for (int i = 0; i < 3; ++i) q[i] = Expr::x(i) - s.pos[i];
  const Vec3 d{s.rot[s.axis], s.rot[3 + s.axis], s.rot[6 + s.axis]};  // the member's axis
  switch (s.kind) {
    case ShapeKind::Sphere: return s.size[0] - sqrt(square(q[0]) + square(q[1]) + square(q[2]));
    case ShapeKind::Segment: {
      const double l = s.size[0];
      Expr t = (q[0] * d[0] + q[1] * d[1] + q[2] * d[2]) * (1.0 / l);
      t = min(max(t, Expr(0.0)), Expr(1.0));
      Expr e = square(q[0] - t * (l * d[0])) + square(q[1] - t * (l * d[1])) + square(q[2] - t * (l * d[2]));
      return -sqrt(e);
    }
    case ShapeKind::Disc: {
      Expr h = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
      Expr rho = sqrt(square(q[0] - h * d[0]) + square(q[1] - h * d[1]) + square(q[2] - h * d[2]));
      return -sqrt(square(h) + square(max(rho - s.size[0], Expr(0.0))));
    }
    case ShapeKind::Block: break;
  }
  return Expr(-1.0);
}

// World bounding box of a reduction (from its support function).
inline void worldBox(const Reduction& r, Vec3& lo, Vec3& hi) {
  for (int i = 0; i < 3; ++i) {
    Vec3 n{0, 0, 0};
    n[i] = 1;
    hi[i] = supportValue(r, n);
    n[i] = -1;
    lo[i] = -supportValue(r, n);
  }
}

// Midpoint lattice count of {f >= 0} at n^3 over the world box.
inline double latticeVolume(const Reduction& r, int n) {
  Vec3 lo, hi;
  worldBox(r, lo, hi);
  double h[3], count = 0;
  for (int i = 0; i < 3; ++i) h[i] = (hi[i] - lo[i]) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        count += unionValue(r, {lo[0] + (i + 0.5) * h[0], lo[1] + (j + 0.5) * h[1], lo[2] + (k + 0.5) * h[2]}) >= 0;
  return count * h[0] * h[1] * h[2];
}

}  // namespace frep::minkowski::test_shapes
