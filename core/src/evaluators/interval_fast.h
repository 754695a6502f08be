// Internal to the core (interval.cpp, eval_interval.cpp, extremum/term_intervals.h): outward
// rounding by one ulp, and the inlined fast path of the common interval ops on finite operands.
// The fast path is bit-identical to applyOp (interval.cpp): the same IEEE operations and the
// same one-ulp outward steps.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "frep/evaluators/interval.h"

namespace frep {
namespace detail {

// One step to the next double above x: std::nextafter(x, inf) without the libm call (this runs
// for every bound of every op). +inf and NaN stay as they are.
// Without branches on the sign: -0 + 0 is +0, then the bits step by +1 (positive) or -1
// (negative: the sign bit, shifted arithmetically, gives -1), which is the same result.
inline double nextUp(double x) {
  if (!(x < std::numeric_limits<double>::infinity())) return x;
  const double y = x + 0.0;
  int64_t bits;
  std::memcpy(&bits, &y, sizeof bits);
  bits += (bits >> 63) | 1;
  double r;
  std::memcpy(&r, &bits, sizeof r);
  return r;
}
inline double up1(double x) { return nextUp(x); }
inline double down1(double x) { return -nextUp(-x); }
inline bool finiteIv(const Interval& a) {
  return std::fabs(a.lo) < std::numeric_limits<double>::infinity() &&
         std::fabs(a.hi) < std::numeric_limits<double>::infinity();
}
// Both intervals finite, by one sum (x - x is 0 only for finite x). A sum that overflows says
// false for finite bounds: the caller then takes applyOp, which gives the same interval.
inline bool finiteIv2(const Interval& a, const Interval& b) {
  const double s = (a.lo + a.hi) + (b.lo + b.hi);
  return s - s == 0.0;
}

// r = op(a, b) for Copy, Neg, Abs, Sqrt, x^2, +, -, *, min and max on finite operands. Returns
// false when the op or its operands are not handled here (the caller then uses applyOp).
// Always inlined: it runs for every node of every box, and the call costs as much as the op.
[[gnu::always_inline]] inline bool fastOp(Op op, const Interval& a, const Interval& b, double imm, Interval& r) {
  switch (op) {
    case Op::Copy:
      if (!finiteIv(a)) return false;
      r = a;
      return true;
    case Op::Neg:
      if (!finiteIv(a)) return false;
      r = Interval(-a.hi, -a.lo);
      return true;
    case Op::Abs:
      if (!finiteIv(a)) return false;
      if (a.lo >= 0.0) r = a;
      else if (a.hi <= 0.0) r = Interval(-a.hi, -a.lo);
      else r = Interval(0.0, std::max(-a.lo, a.hi));
      return true;
    case Op::Sqrt:
      if (!finiteIv(a)) return false;
      if (a.hi <= 0.0) r = Interval(0.0, 0.0);
      else r = Interval(a.lo > 0.0 ? std::max(0.0, down1(std::sqrt(a.lo))) : 0.0, up1(std::sqrt(a.hi)));
      return true;
    case Op::PowI: {
      if (imm != 2.0 || !finiteIv(a)) return false;
      // powInt(x, 2) == x * x; even power, 1 ulp (interval.cpp powIInterval).
      const double minAbs = (a.lo <= 0.0 && a.hi >= 0.0) ? 0.0 : std::min(std::fabs(a.lo), std::fabs(a.hi));
      const double maxAbs = std::max(std::fabs(a.lo), std::fabs(a.hi));
      r = Interval(std::max(down1(minAbs * minAbs), 0.0), up1(maxAbs * maxAbs));
      return true;
    }
    case Op::Add:
      if (!finiteIv2(a, b)) return false;
      r = Interval(down1(a.lo + b.lo), up1(a.hi + b.hi));
      return true;
    case Op::Sub:
      if (!finiteIv2(a, b)) return false;
      r = Interval(down1(a.lo - b.hi), up1(a.hi - b.lo));
      return true;
    case Op::Mul: {
      if (!finiteIv2(a, b)) return false;
      // pairwise: the first of the smallest (largest) product, as min_element (max_element)
      const double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
      r = Interval(down1(std::min(std::min(p0, p1), std::min(p2, p3))),
                   up1(std::max(std::max(p0, p1), std::max(p2, p3))));
      return true;
    }
    case Op::Min:
      if (!finiteIv2(a, b)) return false;
      r = Interval(std::min(a.lo, b.lo), std::min(a.hi, b.hi));
      return true;
    case Op::Max:
      if (!finiteIv2(a, b)) return false;
      r = Interval(std::max(a.lo, b.lo), std::max(a.hi, b.hi));
      return true;
    default:
      return false;
  }
}

// op(a, b): the fast path, else applyOp.
inline Interval applyOpFast(Op op, const Interval& a, const Interval& b) {
  Interval r;
  if (fastOp(op, a, b, 0.0, r)) return r;
  return applyOp(op, a, b);
}

}  // namespace detail
}  // namespace frep
