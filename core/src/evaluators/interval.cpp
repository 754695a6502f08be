// Interval extension of every op (see interval.h for the soundness contract).
//
// Two facts keep this file short:
//  * An input equal to everything() may stand for NaN. Every op that propagates NaN from an
//    input therefore returns everything() for such an input (checked once, up front), and any
//    NaN bound produced along the way also becomes everything().
//  * Bounds are computed from the same libm/IEEE operations the point evaluator uses, then
//    pushed outward: 1 ulp for correctly rounded ops, kTransUlps for libm transcendentals.
#include "frep/evaluators/interval.h"
#include "frep/expressions/pow_int.h"
#include "frep/expressions/sin_cos.h"
#include "evaluators/interval_fast.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace frep {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.141592653589793;
constexpr int kTransUlps = 4;

// Bounds pushed outward by ulps steps of detail::nextUp (interval_fast.h).
inline double up(double x, int ulps = 1) {
  for (int i = 0; i < ulps; ++i) x = detail::nextUp(x);
  return x;
}
inline double down(double x, int ulps = 1) { return -up(-x, ulps); }

bool isEverything(const Interval& a) { return a.lo == -kInf && a.hi == kInf; }
bool hasNaN(const Interval& a) { return std::isnan(a.lo) || std::isnan(a.hi); }
bool finite(const Interval& a) { return std::isfinite(a.lo) && std::isfinite(a.hi); }
bool containsZero(const Interval& a) { return a.lo <= 0.0 && a.hi >= 0.0; }
bool excludesZero(const Interval& a) { return a.lo > 0.0 || a.hi < 0.0; }
bool isZero(const Interval& a) { return a.lo == 0.0 && a.hi == 0.0; }
Interval hull(const Interval& a, const Interval& b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }

// Outward-rounded result of a monotone libm function (increasing: f(lo) <= f(hi)).
template <typename F>
Interval increasing(F f, double lo, double hi, int ulps = kTransUlps) {
  return {down(f(lo), ulps), up(f(hi), ulps)};
}
template <typename F>
Interval decreasing(F f, double lo, double hi, int ulps = kTransUlps) {
  return {down(f(hi), ulps), up(f(lo), ulps)};
}

// Whether some offset + k * period (k integer) may lie in [lo, hi]. Errs towards "yes": the
// tolerance (in periods) is far above the rounding error of the division for |x| <= 1e6.
bool mayHitGrid(double lo, double hi, double offset, double period) {
  constexpr double tol = 1e-9;
  double t0 = (lo - offset) / period, t1 = (hi - offset) / period;
  return std::floor(t1 + tol) >= std::ceil(t0 - tol);
}
constexpr double kMaxPeriodicArg = 1e6;  // beyond this, sin/cos give [-1, 1], tan everything

Interval sinLike(const Interval& a, double maxOffset, double minOffset, double (*f)(double)) {
  if (!finite(a)) return Interval::everything();  // sin(inf) is NaN
  if (a.width() >= 2 * kPi || std::max(-a.lo, a.hi) > kMaxPeriodicArg) return {-1.0, 1.0};
  // f is the evaluators' own sin/cos (sin_cos.h): within kOwnTrigUlps ulps (<= 2^-52 |v| each)
  // plus kOwnTrigAbsErr of the true value, at the endpoints as at every point between, so a
  // monotone piece's values lie within twice that of [f(lo), f(hi)] (absolute: near zeros too).
  const double flo = f(a.lo), fhi = f(a.hi);
  const double m = std::max(std::fabs(flo), std::fabs(fhi));
  const double w = 2 * (kOwnTrigUlps * 0x1p-52 * m + kOwnTrigAbsErr);
  Interval r{down(std::min(flo, fhi) - w, kTransUlps), up(std::max(flo, fhi) + w, kTransUlps)};
  if (mayHitGrid(a.lo, a.hi, maxOffset, 2 * kPi)) r.hi = 1.0;
  if (mayHitGrid(a.lo, a.hi, minOffset, 2 * kPi)) r.lo = -1.0;
  return {std::max(r.lo, -1.0), std::min(r.hi, 1.0)};
}

Interval tanInterval(const Interval& a) {
  if (!finite(a) || a.width() >= kPi || std::max(-a.lo, a.hi) > kMaxPeriodicArg ||
      mayHitGrid(a.lo, a.hi, kPi / 2, kPi))
    return Interval::everything();  // a pole may lie inside
  return increasing(static_cast<double (*)(double)>(std::tan), a.lo, a.hi);
}

double clamp1(double v) { return std::min(1.0, std::max(-1.0, v)); }
double floorLog(double v) { return v > kLogFloor ? v : kLogFloor; }


// Computed powInt is monotone in |x| (products of rounded monotone factors), so endpoints
// bound every computed value; the ulp margin also covers the exact x^n (<= 2 roundings per bit).
Interval powIInterval(const Interval& a, int n) {
  if (n == 0) return {1.0, 1.0};  // powInt(x, 0) == 1 for every x, NaN included
  unsigned m = n < 0 ? -static_cast<unsigned>(n) : static_cast<unsigned>(n);
  int bits = 0;
  for (unsigned k = m; k; k >>= 1) ++bits;
  const int ulps = (n == 2) ? 1 : 2 * bits + 1;
  const bool even = (m & 1u) == 0;
  const double minAbs = containsZero(a) ? 0.0 : std::min(std::fabs(a.lo), std::fabs(a.hi));
  const double maxAbs = std::max(std::fabs(a.lo), std::fabs(a.hi));
  Interval r;
  if (even) {
    if (n > 0) r = {down(powInt(minAbs, n), ulps), up(powInt(maxAbs, n), ulps)};
    else if (minAbs == 0.0) r = {down(powInt(maxAbs, n), ulps), kInf};
    else r = {down(powInt(maxAbs, n), ulps), up(powInt(minAbs, n), ulps)};
    r.lo = std::max(r.lo, 0.0);  // even powers are never negative
  } else {
    if (n > 0) r = {down(powInt(a.lo, n), ulps), up(powInt(a.hi, n), ulps)};
    else if (containsZero(a)) return Interval::everything();  // +-inf at +-0
    else r = {down(powInt(a.hi, n), ulps), up(powInt(a.lo, n), ulps)};
    if (a.lo >= 0.0) r.lo = std::max(r.lo, 0.0);  // the sign of powInt is exact
    if (a.hi <= 0.0) r.hi = std::min(r.hi, 0.0);
  }
  return r;
}

Interval mulInterval(const Interval& a, const Interval& b) {
  double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  for (double v : p)
    if (std::isnan(v)) return Interval::everything();  // 0 * inf may be attained
  return {down(*std::min_element(p, p + 4)), up(*std::max_element(p, p + 4))};
}

Interval divInterval(const Interval& a, const Interval& b) {
  if (containsZero(b)) return Interval::everything();  // x/0 is +-inf or NaN
  double q[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  for (double v : q)
    if (std::isnan(v)) return Interval::everything();  // inf / inf
  return {down(*std::min_element(q, q + 4)), up(*std::max_element(q, q + 4))};
}

// For a positive base, y * log(x) is bilinear in (y, log x), so pow's extremes over the box
// sit at its corners; a base touching 0 adds pow(0, y) in {0, 1}; a negative base or
// 0^negative (which may be -inf at -0) gives everything.
Interval powInterval(const Interval& a, const Interval& b) {
  if (a.lo < 0.0) return Interval::everything();
  if (a.lo == 0.0 && b.lo < 0.0) return Interval::everything();
  double p[4] = {std::pow(a.lo, b.lo), std::pow(a.lo, b.hi), std::pow(a.hi, b.lo), std::pow(a.hi, b.hi)};
  Interval r{*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
  if (a.lo == 0.0) r = hull(r, Interval(0.0, 1.0));
  return {std::max(0.0, down(r.lo, kTransUlps)), up(r.hi, kTransUlps)};
}

// atan2 is continuous away from the origin and the cut (x < 0, y = 0, sign of zero decides);
// elsewhere the angle range over a box is spanned by its corners.
Interval atan2Interval(const Interval& y, const Interval& x) {
  const Interval full{down(-kPi, kTransUlps), up(kPi, kTransUlps)};
  if (containsZero(y) && x.lo <= 0.0) return full;
  double t[4] = {std::atan2(y.lo, x.lo), std::atan2(y.lo, x.hi), std::atan2(y.hi, x.lo), std::atan2(y.hi, x.hi)};
  return {std::max(full.lo, down(*std::min_element(t, t + 4), kTransUlps)),
          std::min(full.hi, up(*std::max_element(t, t + 4), kTransUlps))};
}

// fmod is exact, has the sign of a and |fmod(a, b)| < |b|, |fmod(a, b)| <= |a|.
Interval fmodInterval(const Interval& a, const Interval& b) {
  if (containsZero(b) || !finite(a)) return Interval::everything();  // NaN cases
  const double bMax = std::max(std::fabs(b.lo), std::fabs(b.hi));
  const double bMin = std::min(std::fabs(b.lo), std::fabs(b.hi));
  if (std::max(-a.lo, a.hi) < bMin) return a;  // fmod(a, b) == a
  return {a.lo >= 0.0 ? 0.0 : std::max(a.lo, -bMax), a.hi <= 0.0 ? 0.0 : std::min(a.hi, bMax)};
}

// frac(x) = x - trunc(x) is exact and, where trunc is constant, increasing.
Interval fracInterval(const Interval& a) {
  if (!finite(a)) return Interval::everything();  // inf - inf
  if (std::trunc(a.lo) == std::trunc(a.hi)) return {a.lo - std::trunc(a.lo), a.hi - std::trunc(a.hi)};
  if (a.lo >= 0.0) return {0.0, 1.0};
  if (a.hi <= 0.0) return {-1.0, 0.0};
  return {-1.0, 1.0};
}

// Comparisons: decided when the operand intervals settle the question, else [0, 1].
Interval truth(bool decidedTrue, bool decidedFalse) {
  if (decidedTrue) return {1.0, 1.0};
  if (decidedFalse) return {0.0, 0.0};
  return {0.0, 1.0};
}

Interval compare(Op op, const Interval& a, const Interval& b) {
  if (isEverything(a) || isEverything(b)) return {0.0, 1.0};  // may be NaN
  switch (op) {
    case Op::Lt: return truth(a.hi < b.lo, a.lo >= b.hi);
    case Op::Le: return truth(a.hi <= b.lo, a.lo > b.hi);
    case Op::Gt: return truth(a.lo > b.hi, a.hi <= b.lo);
    case Op::Ge: return truth(a.lo >= b.hi, a.hi < b.lo);
    case Op::Eq: return truth(a.lo == a.hi && b.lo == b.hi && a.lo == b.lo, a.hi < b.lo || b.hi < a.lo);
    case Op::Ne: return truth(a.hi < b.lo || b.hi < a.lo, a.lo == a.hi && b.lo == b.hi && a.lo == b.lo);
    default: return {0.0, 1.0};
  }
}

// Ops whose scalar result is NaN whenever input a (resp. b) is NaN.
// R-functions with -1 < a <= 1 are non-decreasing in both arguments (their partials
// (1 ± (f1 − a f2)/sqrt(f1² + f2² − 2a f1 f2))/(1 + a) are >= 0 because (f1 − a f2)² <= that
// radicand when a² <= 1), so the exact range over a box is [R(lo, lo), R(hi, hi)]. The
// endpoint values cancel catastrophically near 0, so their rounding error is bounded by the
// size of the operands, not of the result (see the slack below).
Interval rFunctionInterval(bool disjunction, const Interval& a, const Interval& b, double alpha) {
  if (!finite(a) || !finite(b)) return Interval::everything();  // inf - inf is NaN at points
  // Monotonicity needs a in (-1, 1] and squares that do not overflow.
  const double big = 1e150;
  if (!(alpha > -1.0 && alpha <= 1.0) || std::max({-a.lo, a.hi, -b.lo, b.hi}) > big) return Interval::everything();
  // Rounding: a computed value (at a corner, or at any point of the box the bound must cover)
  // is off by the radicand's error es through the root, plus a few ulps of the operands. With
  // F1, F2 the largest magnitudes over the box: es <= 4 eps (F1² + F2² + 2|a| F1 F2); the root
  // is off by at most sqrt(2 es) where the radicand cancels (a != 0), by its relative rounding
  // when it cannot (a = 0: a sum of squares). Twice that covers both the corner and the point.
  const double eps = std::numeric_limits<double>::epsilon();
  const double F1 = std::max(std::fabs(a.lo), std::fabs(a.hi)), F2 = std::max(std::fabs(b.lo), std::fabs(b.hi));
  const double s2 = F1 * F1 + F2 * F2;
  const double rootMax = std::sqrt(s2 + 2.0 * std::fabs(alpha) * F1 * F2);
  const double rootErr = alpha == 0.0 ? 4.0 * eps * rootMax : std::sqrt(8.0 * eps * (s2 + 2.0 * std::fabs(alpha) * F1 * F2));
  const double slack = 2.0 * (rootErr + 8.0 * eps * (F1 + F2 + rootMax)) / std::min(1.0, 1.0 + alpha);
  auto bound = [&](double f1, double f2, bool upper) {
    double v = rFunctionValue(disjunction, f1, f2, alpha);
    double w = upper ? up(v + slack, 2) : down(v - slack, 2);
    return std::isnan(w) ? (upper ? kInf : -kInf) : w;
  };
  return {bound(a.lo, b.lo, false), bound(a.hi, b.hi, true)};
}

bool nanFromA(Op op) {
  switch (op) {
    case Op::Sqrt: case Op::Log: case Op::Log10: case Op::Not: case Op::PowI:
    case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
    case Op::And: case Op::Or: case Op::Select:
      return false;
    default:
      return true;
  }
}
bool nanFromB(Op op) {
  switch (op) {
    case Op::Add: case Op::Sub: case Op::Mul: case Op::Div: case Op::Pow: case Op::Atan2:
    case Op::Fmod: case Op::RAnd: case Op::ROr:
      return true;
    default:
      return false;
  }
}

Interval dispatch(Op op, const Interval& a, const Interval& b, const Interval& c, double imm) {
  using Fn = double (*)(double);
  switch (op) {
    case Op::Const: case Op::Var: case Op::Param: case Op::Copy: return a;
    case Op::Extremum: break;  // evaluated by the extremum search, never through here
    case Op::Field: break;     // bounded by its FieldFunction object, never through here
    case Op::Neg: return {-a.hi, -a.lo};
    case Op::Abs:
      if (a.lo >= 0.0) return a;
      if (a.hi <= 0.0) return {-a.hi, -a.lo};
      return {0.0, std::max(-a.lo, a.hi)};
    case Op::Sqrt:
      if (a.hi <= 0.0) return {0.0, 0.0};
      return {a.lo > 0.0 ? std::max(0.0, down(std::sqrt(a.lo))) : 0.0, up(std::sqrt(a.hi))};
    case Op::Exp: {
      Interval r = increasing(static_cast<Fn>(std::exp), a.lo, a.hi);
      return {std::max(r.lo, 0.0), r.hi};
    }
    case Op::Log: return increasing(static_cast<Fn>(std::log), floorLog(a.lo), floorLog(a.hi));
    case Op::Log10: return increasing(static_cast<Fn>(std::log10), floorLog(a.lo), floorLog(a.hi));
    case Op::Sin: return sinLike(a, kPi / 2, -kPi / 2, ownSin);
    case Op::Cos: return sinLike(a, 0.0, kPi, ownCos);
    case Op::Tan: return tanInterval(a);
    case Op::Asin: return increasing(static_cast<Fn>(std::asin), clamp1(a.lo), clamp1(a.hi));
    case Op::Acos: {
      Interval r = decreasing(static_cast<Fn>(std::acos), clamp1(a.lo), clamp1(a.hi));
      return {std::max(r.lo, 0.0), r.hi};
    }
    case Op::Atan: return increasing(static_cast<Fn>(std::atan), a.lo, a.hi);
    case Op::Sinh: return increasing(static_cast<Fn>(std::sinh), a.lo, a.hi);
    case Op::Cosh: {
      double minAbs = containsZero(a) ? 0.0 : std::min(std::fabs(a.lo), std::fabs(a.hi));
      double maxAbs = std::max(std::fabs(a.lo), std::fabs(a.hi));
      Interval r = increasing(static_cast<Fn>(std::cosh), minAbs, maxAbs);
      return {std::max(r.lo, 1.0 - 0x1p-52), r.hi};  // cosh >= 1 (keep a margin below 1)
    }
    case Op::Tanh: {
      Interval r = increasing(static_cast<Fn>(std::tanh), a.lo, a.hi);
      return {std::max(r.lo, -1.0), std::min(r.hi, 1.0)};
    }
    case Op::Floor: return {std::floor(a.lo), std::floor(a.hi)};
    case Op::Ceil: return {std::ceil(a.lo), std::ceil(a.hi)};
    case Op::Trunc: return {std::trunc(a.lo), std::trunc(a.hi)};
    case Op::Frac: return fracInterval(a);
    case Op::PowI:
      if (isEverything(a)) return imm == 0.0 ? Interval(1.0) : Interval::everything();
      return powIInterval(a, static_cast<int>(imm));
    case Op::Not: return truth(isZero(a), excludesZero(a));
    case Op::Add: return {down(a.lo + b.lo), up(a.hi + b.hi)};
    case Op::Sub: return {down(a.lo - b.hi), up(a.hi - b.lo)};
    case Op::Mul: return mulInterval(a, b);
    case Op::Div: return divInterval(a, b);
    case Op::Pow: return powInterval(a, b);
    case Op::Atan2: return atan2Interval(a, b);
    // min(a, NaN) == a and max(a, NaN) == a, so only a NaN in a matters (handled up front).
    case Op::Min: return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
    case Op::Max: return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
    case Op::Fmod: return fmodInterval(a, b);
    case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
      return compare(op, a, b);
    case Op::And: return truth(excludesZero(a) && excludesZero(b), isZero(a) || isZero(b));
    case Op::Or: return truth(excludesZero(a) || excludesZero(b), isZero(a) && isZero(b));
    case Op::RAnd: case Op::ROr: return rFunctionInterval(op == Op::ROr, a, b, imm);
    case Op::Select:  // select(c, t, f) = c != 0 ? t : f; NaN counts as non-zero
      if (excludesZero(a)) return b;
      if (isZero(a)) return c;
      return hull(b, c);
    case Op::Count_: break;
  }
  return Interval::everything();
}

}  // namespace

Interval applyOp(Op op, const Interval& a0, const Interval& b0, const Interval& c0, double imm) {
  const Interval a = hasNaN(a0) ? Interval::everything() : a0;
  const Interval b = hasNaN(b0) ? Interval::everything() : b0;
  const Interval c = hasNaN(c0) ? Interval::everything() : c0;
  const int arity = opArity(op);
  if (nanFromA(op) && arity >= 1 && isEverything(a)) return Interval::everything();
  if (nanFromB(op) && isEverything(b)) return Interval::everything();
  Interval r = dispatch(op, a, b, c, imm);
  if (hasNaN(r)) return Interval::everything();
  return r;
}

}  // namespace frep
