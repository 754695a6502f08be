// The core's own primitives: f >= 0 inside, over the coordinates x0, x1, x2 (x0, x1 for the 2D
// ones). Use remap(f, coords) to evaluate one at transformed coordinates (the language's
// HyperFun primitives do exactly that with their x argument). Parameters are Expr, so they may
// be constants or bound parameters; constant radii / semi-axes must be non-zero
// (std::invalid_argument otherwise).
#pragma once

#include <array>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/primitives/ops.h"

namespace frep {

using Coords2 = std::array<Expr, 2>;
using Coords3 = std::array<Expr, 3>;

// R² − |X − c|² in as many dimensions as c has (x0 .. x_{n-1}).
Expr ball(const std::vector<Expr>& c, const Expr& r);
Expr sphere(const Coords3& c, const Expr& r);
// 1 − Σ ((x_i − c_i) / r_i)².
Expr ellipsoid(const Coords3& c, const Coords3& radii);
// Half-space {X : n·X <= offset}: offset − n·X (n is the outward normal; any dimension).
Expr halfSpace(const std::vector<Expr>& normal, const Expr& offset);
// Axis-aligned box with centre c and half sizes h: the R-intersection (parameter a) of the
// slabs |x_i − c_i| <= h_i, each slab itself the R-intersection of two half-spaces. a = 1 is
// min(h_i − |x_i − c_i|) built from exact min nodes.
Expr block(const Coords3& c, const Coords3& halfSize, const Expr& a = 1.0);

// Infinite circular cylinders along an axis: R² minus the squared distance to the axis line
// through c (c's component along the axis is ignored).
Expr cylinderX(const Coords3& c, const Expr& r);
Expr cylinderY(const Coords3& c, const Expr& r);
Expr cylinderZ(const Coords3& c, const Expr& r);
// Elliptic cylinders: 1 − (d_p / a)² − (d_q / b)², (p, q) = (y, z), (x, z), (x, y) for X, Y, Z.
Expr ellipticCylinderX(const Coords3& c, const Expr& a, const Expr& b);
Expr ellipticCylinderY(const Coords3& c, const Expr& a, const Expr& b);
Expr ellipticCylinderZ(const Coords3& c, const Expr& a, const Expr& b);
// HyperFun-style double cones with apex c: d_axis² − (d_p / r)² − (d_q / r)²; r is the radius
// one unit from the apex.
Expr coneX(const Coords3& c, const Expr& r);
Expr coneY(const Coords3& c, const Expr& r);
Expr coneZ(const Coords3& c, const Expr& r);
// Tori around an axis through c: r0² − (ρ − R)² − d_axis², ρ = distance to the axis.
Expr torusX(const Coords3& c, const Expr& majorR, const Expr& minorR);
Expr torusY(const Coords3& c, const Expr& majorR, const Expr& minorR);
Expr torusZ(const Coords3& c, const Expr& majorR, const Expr& minorR);
// Barr's superellipsoid as HyperFun writes it, with X = (x − cx)/rx etc.:
// 1 − (|X|^(2/s2) + |Y|^(2/s2))^(s2/s1) − |Z|^(2/s1). s1 = s2 = 1 is the ellipsoid.
Expr superellipsoid(const Coords3& c, const Coords3& radii, const Expr& s1, const Expr& s2);

// 2D objects over (x0, x1).
Expr disc(const Coords2& c, const Expr& r);
Expr rectangle(const Coords2& c, const Coords2& halfSize, const Expr& a = 1.0);

}  // namespace frep
