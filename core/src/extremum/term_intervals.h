// Internal to the min-of-terms form (extremum_terms*.cpp): outward-rounded interval operations
// on a box's nodes and the projections constraint propagation makes.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "evaluators/interval_fast.h"
#include "frep/evaluators/interval.h"

namespace frep {
namespace detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Outward-rounded interval ops (interval_fast.h: inlined on finite operands, this runs for every
// node of every box; anything else goes through applyOp).
inline Interval iadd(const Interval& a, const Interval& b) { return applyOpFast(Op::Add, a, b); }
inline Interval isub(const Interval& a, const Interval& b) { return applyOpFast(Op::Sub, a, b); }
inline Interval imul(const Interval& a, const Interval& b) { return applyOpFast(Op::Mul, a, b); }
inline Interval ineg(const Interval& a) { return Interval(-a.hi, -a.lo); }
inline bool isZeroIv(const Interval& a) { return a.lo == 0.0 && a.hi == 0.0; }
// Value of one op over intervals: inlined common cases, else applyOp.
inline Interval ival(Op op, const Interval& a, const Interval& b, const Interval& c, double imm, bool square) {
  if (square) {  // x * x: tighter as x^2 (bit for bit the same values at points)
    op = Op::PowI;
    imm = 2.0;
  }
  if (op == Op::Neg) return ineg(a);  // exact, whatever the bounds
  Interval r;
  if (fastOp(op, a, b, imm, r)) return r;
  return applyOp(op, a, b, c, imm);
}

// x := x intersected with y; false when empty.
inline bool meet(Interval& x, const Interval& y) {
  if (std::isnan(y.lo) || std::isnan(y.hi)) return true;  // no information
  x.lo = std::max(x.lo, y.lo);
  x.hi = std::min(x.hi, y.hi);
  return x.lo <= x.hi;
}
inline bool meetLo(Interval& x, double lo) { return meet(x, Interval(lo, kInf)); }
inline bool meetHi(Interval& x, double hi) { return meet(x, Interval(-kInf, hi)); }
// A lower bound of every a with RAnd_alpha(a, b) >= theta (b fixed; RAnd increases in a towards
// its supremum b): the root a* = theta (2b - theta (1 + alpha)) / (2 (b - theta)) of
// RAnd(a*, b) = theta, lowered by a margin far above its rounding error; -inf when unknown.
inline double rAndInverse(double theta, double b, double alpha) {
  if (!(std::fabs(theta) < kInf) || !(std::fabs(b) < kInf) || !(b > theta)) return -kInf;
  const double a = theta * (2.0 * b - theta * (1.0 + alpha)) / (2.0 * (b - theta));
  if (!std::isfinite(a)) return -kInf;
  // The closed form cancels as b -> theta: trust it only where the denominator is not tiny.
  if (!(b - theta > 1e-6 * (1.0 + std::fabs(b) + std::fabs(theta)))) return -kInf;
  return a - 1e-9 * (1.0 + std::fabs(a) + std::fabs(b) + std::fabs(theta));
}

// x := the part of x outside the open interval (-s, s) (as a hull), s >= 0.
inline bool excludeAround0(Interval& x, double s) {
  if (!(s > 0.0)) return true;
  if (x.lo > -s) return meetLo(x, s);
  if (x.hi < s) return meetHi(x, -s);
  return true;
}

}  // namespace detail
}  // namespace frep
