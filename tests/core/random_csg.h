// Random and regular CSG models for the pruning and plane tests: spheres, half-spaces, R-function
// unions/intersections/differences with a = 1 (min/max, Pasko-Survey) and selects.
#pragma once

#include <cmath>
#include <random>

#include "frep/expressions/expr.h"

namespace frep::testing {

inline Expr sphere(double cx, double cy, double cz, double r) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  return r * r - square(x - cx) - square(y - cy) - square(z - cz);
}

// Union of n spheres on a ring of radius 1.5 in the z = 0 plane (radius 0.4 each).
inline Expr ringOfSpheres(int n) {
  Expr u = sphere(1.5, 0.0, 0.0, 0.4);
  for (int i = 1; i < n; ++i) {
    double t = 2 * 3.141592653589793 * i / n;
    u = max(u, sphere(1.5 * std::cos(t), 1.5 * std::sin(t), 0.0, 0.4));
  }
  return u;
}

// Random CSG tree: union max, intersection min, difference min(a, -b) (Pasko-Survey, R-functions
// with a = 1) and a select on a half-space.
inline Expr randomCsg(std::mt19937_64& rng, int depth) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  if (depth == 0 || rng() % 6 == 0) {
    if (rng() % 4 == 0) {  // plane n.x <= d
      double nx = u(rng), ny = u(rng), nz = u(rng);
      return 0.3 * u(rng) - nx * Expr::x(0) - ny * Expr::x(1) - nz * Expr::x(2);
    }
    return sphere(u(rng), u(rng), u(rng), 0.2 + 0.3 * std::fabs(u(rng)));
  }
  Expr a = randomCsg(rng, depth - 1), b = randomCsg(rng, depth - 1);
  switch (rng() % 4) {
    case 0: return max(a, b);
    case 1: return min(a, b);
    case 2: return min(a, -b);
    default: return select(gt(Expr::x(int(rng() % 3)), u(rng)), a, b);
  }
}

}  // namespace frep::testing
