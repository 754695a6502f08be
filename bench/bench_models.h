// Models shared by the benchmarks (one definition, so every figure refers to the same shapes).
#pragma once

#include "frep/expr.h"

namespace frep::bench {

inline Expr sphereModel() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  return 0.64 - square(x) - square(y) - square(z);
}

// A CSG part of about 100 nodes: a plate with a 4x4 grid of drilled holes, four corner bosses
// and a blended-in cross rib, combined with min/max (exact R-functions, a = 1) so that interval
// evaluation can prune whole branches.
inline Expr csgModel() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr plate = min(min(min(0.8 - x, x + 0.8), min(0.8 - y, y + 0.8)), min(0.15 - z, z + 0.15));
  Expr holes;
  bool first = true;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double cx = -0.6 + 0.4 * i, cy = -0.6 + 0.4 * j;
      Expr hole = 0.01 - square(x - cx) - square(y - cy);
      holes = first ? hole : max(holes, hole);
      first = false;
    }
  Expr part = min(plate, -holes);
  for (int c = 0; c < 4; ++c) {
    double cx = (c & 1) ? 0.55 : -0.55, cy = (c & 2) ? 0.55 : -0.55;
    Expr boss = 0.04 - square(x - cx) - square(y - cy) - square(z - 0.2);
    part = max(part, boss);
  }
  Expr rib = min(min(0.05 - abs(x), 0.6 - abs(y)), min(0.35 - z, z));
  return max(part, rib);
}

}  // namespace frep::bench
