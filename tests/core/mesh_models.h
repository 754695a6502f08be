// Analytic test models of the mesher and simplifier tests (inside: f >= 0) and their grids.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/geometry/distance_fields.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

namespace mesh_models {

using frep::Expr;

inline Expr X() { return Expr::x(0); }
inline Expr Y() { return Expr::x(1); }
inline Expr Z() { return Expr::x(2); }

inline Expr sphereAt(double cx, double cy, double cz, double r) {
  return r * r - square(X() - cx) - square(Y() - cy) - square(Z() - cz);
}
// hfBlock-like: min of the six half-spaces, centre c, half sizes h.
inline Expr blockAt(double cx, double cy, double cz, double hx, double hy, double hz) {
  return min(min(min(hx - (X() - cx), hx + (X() - cx)), min(hy - (Y() - cy), hy + (Y() - cy))),
             min(hz - (Z() - cz), hz + (Z() - cz)));
}
inline Expr torusZ(double R, double r) { return r * r - square(sqrt(square(X()) + square(Y())) - R) - square(Z()); }

// An L-shaped prism [0,2]x[0,1] ∪ [0,1]x[0,2] times [0, h] as a closed mesh: the L hexagon
// extruded (not convex: the union of the two blocks).
inline Expr lPrismMesh(double h) {
  const double L[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<double> xyz;
  for (double z : {0.0, h})
    for (const auto& p : L) xyz.insert(xyz.end(), {p[0], p[1], z});
  // The hexagon as four triangles (fan from the reflex vertex 3), counter-clockwise from +z.
  const uint32_t cap[4][3] = {{3, 4, 5}, {3, 5, 0}, {3, 0, 1}, {3, 1, 2}};
  std::vector<uint32_t> tris;
  for (const auto& t : cap) {
    tris.insert(tris.end(), {t[0] + 6, t[1] + 6, t[2] + 6});  // top, outward +z
    tris.insert(tris.end(), {t[0], t[2], t[1]});              // bottom, outward -z
  }
  for (uint32_t i = 0; i < 6; ++i) {
    const uint32_t j = (i + 1) % 6;
    tris.insert(tris.end(), {i, j, j + 6});
    tris.insert(tris.end(), {i, j + 6, i + 6});
  }
  auto m = std::make_shared<frep::MeshField>(xyz, tris, "L prism");
  return frep::fieldExpr(m, X(), Y(), Z());
}

constexpr double kPi = 3.14159265358979323846;

inline frep::GridSpec cubeGrid(double half, int res) {
  return frep::GridSpec::fromBounds({-half, -half, -half}, {half, half, half}, res);
}

// The torus of radii R, r about the z axis as a closed mesh of nu x nv quads, two triangles
// each (xyz: 3 coordinates a vertex; tris: 3 indices a triangle).
struct TorusSoup {
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
};
inline TorusSoup torusSoup(double R, double r, int nu, int nv) {
  TorusSoup s;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, w = 2 * M_PI * j / nv;
      s.xyz.insert(s.xyz.end(),
                   {(R + r * std::cos(w)) * std::cos(u), (R + r * std::cos(w)) * std::sin(u), r * std::sin(w)});
    }
  auto id = [&](int i, int j) { return uint32_t((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      s.tris.insert(s.tris.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
  return s;
}

}  // namespace mesh_models
