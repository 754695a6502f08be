// Analytic test models of the mesher and simplifier tests (inside: f >= 0) and their grids.
#pragma once

#include "frep/expressions/expr.h"
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

constexpr double kPi = 3.14159265358979323846;

inline frep::GridSpec cubeGrid(double half, int res) {
  return frep::GridSpec::fromBounds({-half, -half, -half}, {half, half, half}, res);
}

}  // namespace mesh_models
