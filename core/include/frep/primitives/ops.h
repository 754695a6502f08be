// The operation library: set-theoretic, blending, offsetting, Cartesian product, bijective
// mappings and metamorphosis, all as functions that build Expr. Because the results are plain
// expression DAGs, every evaluator, interval pruning and derivative() work on them unchanged.
//
// Inside is f >= 0. Parameters are Expr so they may be constants, bound parameters or even
// fields (the survey allows a = a(f1, f2)); checks that need a value (ranges, zero divisors)
// run only when the argument is a constant and throw std::invalid_argument.
#pragma once

#include <array>

#include <cstdint>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep {

// ---- Set-theoretic operations: R-functions (Pasko-Survey, "Базовые операции";
// Pasko-Minkowski §3.2 eq. 3.3 for the a = 0 intersection) ----

// (f1 + f2 ± sqrt(f1² + f2² − 2a·f1·f2)) / (1 + a), a in (−1, 1].
// a = 1 gives exact max/min nodes (interval pruning can decide them); a = 0 is the sqrt system
// HyperFun uses. The sign of the result is the sign of max (union) / min (intersection).
Expr rUnion(const Expr& f1, const Expr& f2, const Expr& a = 0.0);
Expr rIntersection(const Expr& f1, const Expr& f2, const Expr& a = 0.0);
Expr rNegation(const Expr& f);
Expr rSubtraction(const Expr& f1, const Expr& f2, const Expr& a = 0.0);  // f1 & ~f2

// Rvachev's C^m system R_0^m: (f1 + f2 ± sqrt(f1² + f2²)) · (f1² + f2²)^(m/2), m >= 0.
// (The survey notes C^k systems exist; this is the standard member of that family.)
Expr rUnionSmooth(const Expr& f1, const Expr& f2, double m);
Expr rIntersectionSmooth(const Expr& f1, const Expr& f2, double m);

// Solid ∩ box: min(f, x - lo, hi - x, ...) over x[0..2], written so that a NaN of f stays a NaN
// (outside): min's operands are reordered when nodes are shared, and min(face, NaN) is the face.
// What frep mesh and frep sample compute where the box cuts the solid (JobSpec cut_lo/cut_hi).
Expr cutByBox(const Expr& f, const std::array<double, 3>& lo, const std::array<double, 3>& hi);

// ---- Blending (Pasko-Survey, blending: B = R(f1, f2) + a0 / (1 + (f1/a1)² + (f2/a2)²)) ----
// a0 > 0 adds material along the common edge, a0 < 0 removes it; a1, a2 != 0 set its extent.
// `a` is the parameter of the underlying R-function (HyperFun's hfBlendUni/Int use a = 0).
Expr blendDisplacement(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                       const Expr& a2);
Expr blendUnion(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                const Expr& a2, const Expr& a = 0.0);
Expr blendIntersection(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                       const Expr& a2, const Expr& a = 0.0);

// ---- Offsets (Pasko-Survey, offsetting forms 1 and 2; form 3 is the extremum node's job) ----
Expr offsetConst(const Expr& f, const Expr& c);  // f + C
// f(X + D·∇f/|∇f|) over all coordinates f uses; the gradient is symbolic (derivative()), and
// where |∇f| = 0 the point is not moved. With f increasing inward, D > 0 grows the solid.
Expr offsetNormal(const Expr& f, const Expr& d);

// ---- Cartesian product (Pasko-Survey, Cartesian product; Pasko-Minkowski eq. 3.2) ----
// f3(x_0..x_{n1-1}, x_{n1}..x_{n1+n2-1}) = f1(x_0..x_{n1-1}) & f2(x_{n1}..), where f2's own
// coordinates x_0..x_{n2-1} are shifted up by n1 (n2 = numVars(f2)). f1 must use only x < n1.
Expr product(const Expr& f1, uint32_t n1, const Expr& f2, const Expr& a = 0.0);

// ---- Bijective mappings (Pasko-Survey, bijective mapping: F = f(q(X)), q = g⁻¹) ----
// forward is g (where a point of the original solid goes), inverse is q (the point a deformed
// field reads). apply(f) gives the deformed solid f(q(X)). Vectors are indexed by coordinate;
// coordinates beyond their size are left unchanged.
struct Mapping {
  std::vector<Expr> forward;
  std::vector<Expr> inverse;
  Expr apply(const Expr& f) const { return remap(f, inverse); }
  Mapping inverted() const { return {inverse, forward}; }
  // Composition: first this mapping, then `next` (apply gives next.apply(this->apply(f))).
  Mapping then(const Mapping& next) const;
};

enum class Axis : uint32_t { X = 0, Y = 1, Z = 2 };

// Affine: f(B(X − C)), B = A⁻¹ an n×n row-major matrix (Pasko-Survey, affine case).
// B must be invertible (the forward map needs A); n = c.size(), b.size() = n².
Mapping affineMap(const std::vector<double>& b, const std::vector<double>& c);
Mapping translateMap(const std::vector<Expr>& d);         // moves the solid by +d
Mapping scaleMap(const std::vector<Expr>& s);             // scales by s about the origin
Mapping rotateMap(Axis axis, const Expr& angle);          // right-handed, radians
// Twist about `axis`: the cross-section at height u turns by angle(u) = lerp from angle1 at u1
// to angle2 at u2 (not clamped, as HyperFun's hfTwist*). u1 != u2.
Mapping twistMap(Axis axis, const Expr& u1, const Expr& u2, const Expr& angle1,
                 const Expr& angle2);
Mapping twistRateMap(Axis axis, const Expr& radiansPerUnit);  // angle(u) = rate·u
// Taper along `axis`: the two other coordinates are scaled by s(u), s1 below u1, s2 above u2,
// linear between (as HyperFun's hfTaper*). Constant s1, s2 must be non-zero of one sign.
Mapping taperMap(Axis axis, const Expr& u1, const Expr& u2, const Expr& s1, const Expr& s2);
// Bend: the `along` axis is wrapped around a circle of the given radius whose centre lies at
// distance radius on the positive `toward` axis; a point at (u, v) goes to the circle of radius
// (radius − v) at angle u/radius. Bijective for |u| < π·radius, v < radius. radius != 0.
Mapping bendMap(Axis along, Axis toward, const Expr& radius);
// A solid described in cylindrical coordinates (x0 = r, x1 = phi, x2 = z) placed in Cartesian
// space: apply(f) = f(sqrt(x²+y²), atan2(y, x), z). inverted() maps a Cartesian solid into
// (r, phi, z) space: f(r cos phi, r sin phi, z).
Mapping cylindricalToCartesianMap();

// Convenience wrappers: the mapping applied to f.
Expr affine(const Expr& f, const std::vector<double>& b, const std::vector<double>& c);
Expr translate(const Expr& f, const std::vector<Expr>& d);
Expr scale(const Expr& f, const std::vector<Expr>& s);
Expr rotateX(const Expr& f, const Expr& angle);
Expr rotateY(const Expr& f, const Expr& angle);
Expr rotateZ(const Expr& f, const Expr& angle);
Expr twist(const Expr& f, Axis axis, const Expr& u1, const Expr& u2, const Expr& angle1,
           const Expr& angle2);
Expr twistRate(const Expr& f, Axis axis, const Expr& radiansPerUnit);
Expr taper(const Expr& f, Axis axis, const Expr& u1, const Expr& u2, const Expr& s1,
           const Expr& s2);
Expr bend(const Expr& f, Axis along, Axis toward, const Expr& radius);
Expr cylindricalToCartesian(const Expr& f);
Expr cartesianToCylindrical(const Expr& f);

// ---- Metamorphosis ----
// f1·(1 − g) + f2·g, g a weight in [0, 1] (Pasko-Survey, metamorphosis).
Expr morph(const Expr& f1, const Expr& f2, const Expr& g);
// The (n+1)-D object of the survey: f1, f2 over x_0..x_{n-1}; g(x_n) rises linearly from 0 at
// x_n = x0 to 1 at x_n = x1 and is clamped outside. x0 != x1.
Expr morphAlongAxis(const Expr& f1, const Expr& f2, uint32_t n, double x0, double x1);
// β·F1 + (1 − β)·F2 (Vyatkin-Perturbation eq. 17): morph with g = 1 − β.
Expr morphLinear(const Expr& f1, const Expr& f2, const Expr& beta);

}  // namespace frep
