// Closed intervals [lo, hi] with sound (outward-rounded) arithmetic.
//
// Soundness contract: for every op, if each input x lies in its interval X, then op(x) lies in
// op(X). NaN-producing cases (0/0, pow of a negative base, ...) widen to [-inf, +inf], so a box
// where the value may be undefined is always "ambiguous". Rounding: each bound is pushed one ulp
// outward with nextafter, which covers the <= 1 ulp error of IEEE + - * / sqrt and the few-ulp
// error of libm transcendentals (those get a wider, 4-ulp, margin).
#pragma once

#include <limits>

#include "frep/expressions/expr.h"

namespace frep {

struct Interval {
  double lo = 0.0, hi = 0.0;
  Interval() = default;
  Interval(double v) : lo(v), hi(v) {}  // NOLINT
  Interval(double l, double h) : lo(l), hi(h) {}
  static Interval everything() {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  bool contains(double v) const { return v >= lo && v <= hi; }
  double width() const { return hi - lo; }
  double mid() const { return 0.5 * (lo + hi); }
};

// Interval extension of one op (imm: the PowI exponent).
Interval applyOp(Op op, const Interval& a, const Interval& b = Interval(), const Interval& c = Interval(),
                 double imm = 0.0);

}  // namespace frep
