// Models shared by the benchmarks (one definition, so every figure refers to the same shapes).
#pragma once

#include <array>

#include "frep/expressions/expr.h"
#include "frep/primitives/ops.h"

namespace frep::bench {

inline Expr sphereModel() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  return 0.64 - square(x) - square(y) - square(z);
}
inline const std::array<double, 3> kSphereLo{-1, -1, -1}, kSphereHi{1, 1, 1};

// The CSG part (111 DAG nodes before R-function fusion): a 4 x 2.4 x 1 plate with a 4 x 4 grid
// of vertical cylindrical holes (max/min CSG), cut by an a = 0 R-intersection, with three
// spheres R-unioned on top (Pasko-Survey R-functions).
inline Expr csgModel() {
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr block = min(min(2.0 - abs(X), 1.2 - abs(Y)), 0.5 - abs(Z));
  Expr holes;
  bool first = true;
  for (double cx : {-1.5, -0.5, 0.5, 1.5})
    for (double cy : {-0.9, -0.3, 0.3, 0.9}) {
      Expr cyl = 0.04 - square(X - cx) - square(Y - cy);
      holes = first ? cyl : max(holes, cyl);
      first = false;
    }
  Expr plate = rIntersection(block, -holes, 0.0);
  Expr bumps = max(max(0.36 - square(X + 1.0) - square(Y) - square(Z - 0.5),
                       0.36 - square(X - 1.0) - square(Y) - square(Z - 0.5)),
                   0.25 - square(X) - square(Y - 0.6) - square(Z - 0.5));
  return rUnion(plate, bumps, 0.0);
}
inline const std::array<double, 3> kCsgLo{-2.2, -2.2, -2.2}, kCsgHi{2.2, 2.2, 2.2};

// The unit ball intersected with a gyroid sheet (|g| < 0.3, period 2 pi / 8): libfive's
// showcase model, 3 sin/cos pairs per point.
inline Expr gyroidModel() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr X = 8.0 * x, Y = 8.0 * y, Z = 8.0 * z;
  Expr g = sin(X) * cos(Y) + sin(Y) * cos(Z) + sin(Z) * cos(X);
  return min(1.0 - square(x) - square(y) - square(z), 0.3 - abs(g));
}
inline const std::array<double, 3> kGyroidLo{-1.1, -1.1, -1.1}, kGyroidHi{1.1, 1.1, 1.1};

}  // namespace frep::bench
