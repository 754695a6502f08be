// Forward error analysis of a tape over a box (float_error.h), one pass in tape order. Each
// register carries an enclosure [lo, hi] of its exact real value (outward-rounded interval
// arithmetic) and two absolute error bounds, ef for the float evaluation and ed for the double
// one, both measured from the exact value, so |f_float - f_double| <= ef + ed at the result.
// Rounding model (Higham, Accuracy and Stability of Numerical Algorithms, eq. 2.4, with an
// absolute term for underflow): fl(x op y) = (x op y)(1 + d) + t, |d| <= u, |t| <= tiny, for
// + - * sqrt, with u = 2^-24 (float) or 2^-53 (double); tiny = 2^-126 also covers flush-to-zero.
// The batch evaluator's fused chains run the same ops in the same order (eval_batch.cpp, built
// with -ffp-contract=off), so the model holds for them too.
#include "frep/evaluators/float_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

namespace frep {
namespace {

constexpr double kUf = 0x1p-24, kUd = 0x1p-53;
constexpr double kTinyF = 0x1p-126, kTinyD = 0x1p-1022;
// Beyond this a float value might overflow: no bound.
constexpr double kMaxMagnitude = 1e30;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Outward steps for values computed in double with round-to-nearest: a relative margin of a few
// ulps plus an absolute one for subnormal results.
inline double dn(double x) { return x - std::fabs(x) * 0x1p-50 - 0x1p-1000; }
inline double up(double x) { return x + std::fabs(x) * 0x1p-50 + 0x1p-1000; }
// The error formulas sum and multiply a handful of nonnegative terms, each rounding <= 2^-53
// relative: this factor restores an upper bound.
inline double upErr(double e) { return e * (1.0 + 0x1p-45); }

inline double mag(double lo, double hi) { return std::max(std::fabs(lo), std::fabs(hi)); }

bool supported(Op op, double imm) {
  switch (op) {
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Neg:
    case Op::Abs:
    case Op::Min:
    case Op::Max:
    case Op::Sqrt:
    case Op::Copy:
      return true;
    case Op::PowI:
      return imm == 2.0;
    case Op::Div:
      return true;
    case Op::RAnd:
    case Op::ROr:
      return imm > -1 && imm < 1;  // the R-functions' parameter range (expr.h)
    default:
      return false;
  }
}

inline bool binary(Op op) {
  return op == Op::Add || op == Op::Sub || op == Op::Mul || op == Op::Min || op == Op::Max || op == Op::Div ||
         op == Op::RAnd || op == Op::ROr;
}

// The R-function parameter (DenseTape has no R-functions: never read there).
inline double rParam(const Instr& ins) { return ins.imm; }
inline double rParam(const DenseInstr&) { return 0.0; }

// (x + y + sg sqrt(x^2 + y^2 - 2 al x y)) / (1 + al) in double, as the enclosure's end points
// (R-functions are increasing in both arguments, expr.h); widened outwards by `side`.
inline double rValue(double x, double y, double al, double sg, double side) {
  const double q = std::max(0.0, x * x + y * y - 2 * al * x * y);
  const double v = (x + y + sg * std::sqrt(q)) / (1 + al);
  return v + side * (std::fabs(v) * 0x1p-48 + (std::fabs(x) + std::fabs(y)) * 0x1p-48 + 0x1p-1000);
}

// Rounding error of the batch evaluator's R-function (eval_batch.cpp: s = a a + b b - (2 al) a
// b, root = sqrt(max(s, 0)), (a + b + sg root) / (1 + al); no division when al = 0) at inputs
// of magnitudes at most ma, mb, with unit roundoff u, underflow term tiny and the precision's
// parameter off from al by at most dal; mr bounds the result's magnitude. The squares and
// products have a relative error of at most theta against Q = a^2 + b^2 - 2 al a b >= (1 -
// |al|)(a^2 + b^2) (Higham eq. 2.4 per op), so the root one of theta / 2 + u (plus the root of
// the tiny terms), the sum and the final addition u of their magnitudes; al != 0 adds the
// division by the rounded 1 + al.
inline double rRounding(double ma, double mb, double mr, double al, double u, double tiny, double dal) {
  const double aa = std::fabs(al), m = ma + mb;
  const double rmax = std::sqrt(1 + aa) * std::sqrt(ma * ma + mb * mb);  // sqrt(Q) <= sqrt(1 + |al|) |(a, b)|
  if (al == 0) {
    const double root = rmax * (2 * u * (1 + 2 * u)) + 2 * std::sqrt(4 * tiny) + tiny;  // (1 -+ u)^2 around 1
    return u * m + root + u * (mr + u * (m + 3 * rmax)) + 4 * tiny;
  }
  const double theta = (u * 8 * (1 + aa) + 2 * dal) / (1 - aa);
  const double root = rmax * (theta + 2 * u) + 4 * std::sqrt(6 * tiny) + 2 * tiny;
  const double num = m + rmax, eNum = u * m + root + 2 * u * num + 4 * tiny;
  // 1 + al rounded: off from the exact 1 + al by dD; dividing by it
  const double d = 1 + al, dD = dal + 2 * u * (1 + aa), dmin = d - dD;
  if (!(dmin > 0)) return kInf;
  return (eNum + num * dD / d) / dmin + 2 * u * (num + eNum) / dmin + 2 * tiny;
}

// Bounds on |dR/da| and |dR/db| of an R-function with al = 0, R = a + b + sg sqrt(a^2 + b^2),
// over the box [alo, ahi] x [blo, bhi]: dR/da = 1 + sg h(a, b), h = a / sqrt(a^2 + b^2), which
// increases with a and is monotone in b^2 for each sign of a, so its extremes lie at the corners
// (a, b^2). A box holding (0, 0) gets the global bound 2 (the root is 1-Lipschitz).
inline std::pair<double, double> rSlopes(double alo, double ahi, double blo, double bhi, double sg) {
  auto range = [](double lo, double hi, double olo, double ohi) {  // h over [lo, hi] x [olo, ohi]
    const double t0 = olo <= 0 && ohi >= 0 ? 0.0 : std::min(olo * olo, ohi * ohi), t1 = std::max(olo * olo, ohi * ohi);
    if (lo <= 0 && hi >= 0 && t0 == 0) return std::pair<double, double>{-1.0, 1.0};
    double mn = 1, mx = -1;
    for (double x : {lo, hi})
      for (double t : {t0, t1}) {
        const double h = x == 0 ? 0.0 : t == 0 ? (x > 0 ? 1.0 : -1.0) : x / std::sqrt(x * x + t);
        mn = std::min(mn, h), mx = std::max(mx, h);
      }
    return std::pair<double, double>{mn, mx};
  };
  const auto [ha0, ha1] = range(alo, ahi, blo, bhi);
  const auto [hb0, hb1] = range(blo, bhi, alo, ahi);
  // |1 + sg h| over [h0, h1] (within [0, 2]), plus a margin for h's own rounding
  const double da = sg > 0 ? 1 + ha1 : 1 - ha0, db = sg > 0 ? 1 + hb1 : 1 - hb0;
  return {std::min(2.0, da + 1e-9), std::min(2.0, db + 1e-9)};
}
}  // namespace

bool FloatErrorBound::supports(const Tape& tape) {
  if (tape.hasExtrema()) return false;
  for (const Instr& ins : tape.code())
    if (!supported(ins.op, ins.imm)) return false;
  return true;
}

void FloatErrorBound::enterConstants(const std::vector<double>& uni) {
  if (regs_.size() < uni.size()) regs_.resize(uni.size());
  for (size_t r = 0; r < uni.size(); ++r) {
    const double c = uni[r];
    // float(c) - c is exact in double (both on c's binade grid, |difference| < 2^-24 |c|)
    regs_[r] = {c, c, std::fabs(double(float(c)) - c), 0.0};
  }
}

double FloatErrorBound::bound(const Tape& tape, const Interval* box) {
  regs_.resize(tape.numRegs());
  enterConstants(tape.uniforms());
  for (uint32_t v = 0; v < tape.numVars(); ++v) {
    const Interval& x = box[v];
    if (!(mag(x.lo, x.hi) < kMaxMagnitude)) return kInf;
    regs_[tape.varReg(v)] = {x.lo, x.hi, upErr(kUf * mag(x.lo, x.hi) + kTinyF), 0.0};
  }
  for (const Instr& ins : tape.code())
    if (!supported(ins.op, ins.imm)) return kInf;
  return propagate(tape.code().data(), tape.size(), tape.resultReg());
}

void FloatErrorBound::bind(const Tape& root) { enterConstants(root.uniforms()); }

double FloatErrorBound::bound(const DenseTape& tape, const Interval* box) {
  if (regs_.size() < tape.numRegs) regs_.resize(tape.numRegs);
  for (uint32_t v = 0; v < tape.numVars; ++v) {
    const Interval& x = box[v];
    if (!(mag(x.lo, x.hi) < kMaxMagnitude)) return kInf;
    regs_[tape.numUniforms + v] = {x.lo, x.hi, upErr(kUf * mag(x.lo, x.hi) + kTinyF), 0.0};
  }
  return propagate(tape.code.data(), tape.size(), tape.result);
}

// One pass in tape order over instructions of the covered ops (PowI: squares).
template <typename I>
double FloatErrorBound::propagate(const I* code, size_t size, uint32_t result) {
  for (size_t k = 0; k < size; ++k) {
    const I& ins = code[k];
    const Reg a = regs_[ins.a];
    const Reg b = binary(ins.op) ? regs_[ins.b] : a;
    const double ma = mag(a.lo, a.hi), mb = mag(b.lo, b.hi);
    Reg o = a;
    // Rounded result: propagated error pf / pd, then the op's own rounding of a value whose
    // magnitude is at most |exact| + propagated error.
    auto rounded = [&](double pf, double pd) {
      const double m = mag(o.lo, o.hi);
      o.ef = upErr(pf + kUf * (m + pf) + kTinyF);
      o.ed = upErr(pd + kUd * (m + pd) + kTinyD);
    };
    switch (ins.op) {
      case Op::Add:
        o.lo = dn(a.lo + b.lo), o.hi = up(a.hi + b.hi);
        rounded(a.ef + b.ef, a.ed + b.ed);
        break;
      case Op::Sub:
        o.lo = dn(a.lo - b.hi), o.hi = up(a.hi - b.lo);
        rounded(a.ef + b.ef, a.ed + b.ed);
        break;
      case Op::Mul: {
        const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
        o.lo = dn(*std::min_element(p, p + 4)), o.hi = up(*std::max_element(p, p + 4));
        // |a'b' - ab| <= |a| |b' - b| + |b| |a' - a| + |a' - a| |b' - b|
        rounded(ma * b.ef + mb * a.ef + a.ef * b.ef, ma * b.ed + mb * a.ed + a.ed * b.ed);
        break;
      }
      case Op::PowI: {  // squares only (supported)
        const double l2 = a.lo * a.lo, h2 = a.hi * a.hi;
        o.lo = a.lo >= 0 || a.hi <= 0 ? dn(std::min(l2, h2)) : 0.0;
        o.hi = up(std::max(l2, h2));
        // |a'^2 - a^2| = |a' - a| |a' + a| <= e (2|a| + e)
        rounded(a.ef * (2 * ma + a.ef), a.ed * (2 * ma + a.ed));
        break;
      }
      case Op::Sqrt: {
        // sqrt(max(a, 0)): the clamp is 1-Lipschitz; |sqrt(c') - sqrt(c)| <= sqrt(|c' - c|),
        // and <= |c' - c| / sqrt(c) when c >= lo > 0.
        const double clo = std::max(a.lo, 0.0), chi = std::max(a.hi, 0.0);
        o.lo = clo > 0 ? dn(std::sqrt(clo)) : 0.0, o.hi = up(std::sqrt(chi));
        auto prop = [&](double e) {
          const double s = up(std::sqrt(e));
          return o.lo > 0 ? std::min(s, e / o.lo) : s;
        };
        rounded(prop(a.ef), prop(a.ed));
        break;
      }
      case Op::Div: {
        // a / b with b away from 0 in both precisions: |a'/b' - a/b| <= (|b| ea + |a| eb) / (|b'| |b|)
        const double bmin = b.lo > 0 ? b.lo : b.hi < 0 ? -b.hi : 0.0;
        if (!(bmin > 0) || !(bmin - b.ef > 0) || !(bmin - b.ed > 0)) return kInf;
        const double p[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
        o.lo = dn(*std::min_element(p, p + 4)), o.hi = up(*std::max_element(p, p + 4));
        rounded(up((mb * a.ef + ma * b.ef) / (dn(bmin - b.ef) * bmin)),
                up((mb * a.ed + ma * b.ed) / (dn(bmin - b.ed) * bmin)));
        break;
      }
      case Op::RAnd:
      case Op::ROr: {
        // Inputs off by ea, eb move the exact value by at most La ea + Lb eb (mean value theorem
        // over the box widened by the errors; al != 0: sqrt(Q) is the norm of M^(1/2) (a, b), M's
        // eigenvalues 1 -+ al, so it is sqrt(1 + |al|)-Lipschitz).
        const double al = rParam(ins), sg = ins.op == Op::ROr ? 1.0 : -1.0;
        o.lo = rValue(a.lo, b.lo, al, sg, -1.0), o.hi = rValue(a.hi, b.hi, al, sg, 1.0);
        double La = (1 + std::sqrt(1 + std::fabs(al))) / (1 + al) * (1 + 0x1p-40), Lb = La;
        if (al == 0) std::tie(La, Lb) = rSlopes(a.lo - a.ef, a.hi + a.ef, b.lo - b.ef, b.hi + b.ef, sg);
        const double pf = La * a.ef + Lb * b.ef, pd = La * a.ed + Lb * b.ed, mr = mag(o.lo, o.hi);
        const double dalF = std::fabs(double(float(al)) - al);  // the float lanes' parameter
        o.ef = upErr(pf + rRounding(ma + a.ef, mb + b.ef, mr + pf, al, kUf, kTinyF, dalF)) * 1.0625;
        o.ed = upErr(pd + rRounding(ma + a.ed, mb + b.ed, mr + pd, al, kUd, kTinyD, 0.0)) * 1.0625;
        break;
      }
      case Op::Neg:
        o.lo = -a.hi, o.hi = -a.lo;
        break;
      case Op::Abs:
        o.lo = a.lo >= 0 ? a.lo : a.hi <= 0 ? -a.hi : 0.0, o.hi = ma;
        break;
      case Op::Min:
      case Op::Max:
        // min and max move by at most the larger of their inputs' errors, with no rounding
        o.lo = ins.op == Op::Min ? std::min(a.lo, b.lo) : std::max(a.lo, b.lo);
        o.hi = ins.op == Op::Min ? std::min(a.hi, b.hi) : std::max(a.hi, b.hi);
        o.ef = std::max(a.ef, b.ef), o.ed = std::max(a.ed, b.ed);
        break;
      default:  // Copy
        break;
    }
    // Every float value stays below kMaxMagnitude + ef: far from overflow (NaN fails too).
    if (!(mag(o.lo, o.hi) + o.ef < kMaxMagnitude)) return kInf;
    regs_[ins.out] = o;
  }
  const Reg& r = regs_[result];
  return upErr(r.ef + r.ed);
}

}  // namespace frep
