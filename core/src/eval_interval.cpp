// Interval evaluator: one walk of the tape over a box, recording for each min/max/select
// whether the box decides it, so the tape can be pruned for everything inside the box.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "frep/eval.h"
#include "frep/extremum.h"

namespace frep {

namespace {

// A choice is recorded only when it reproduces the scalar rule bit for bit at every point:
//   min: b < a ? b : a  -> KeepA iff b >= a everywhere (ties keep a), KeepB iff b < a everywhere
//   max: b > a ? b : a  -> KeepA iff b <= a everywhere,               KeepB iff b > a everywhere
//   select(c, t, f)     -> KeepA (t) iff c != 0 everywhere,          KeepB (f) iff c == 0 everywhere
// A possibly-NaN operand is everything() and so never satisfies a strict bound it would break.
Choice decide(Op op, const Interval& a, const Interval& b) {
  switch (op) {
    case Op::Min:
      if (a.hi <= b.lo) return Choice::KeepA;
      if (b.hi < a.lo) return Choice::KeepB;
      return Choice::Both;
    case Op::Max:
      if (b.hi <= a.lo) return Choice::KeepA;
      if (b.lo > a.hi) return Choice::KeepB;
      return Choice::Both;
    case Op::Select:
      if (a.lo > 0.0 || a.hi < 0.0) return Choice::KeepA;
      if (a.lo == 0.0 && a.hi == 0.0) return Choice::KeepB;
      return Choice::Both;
    default:
      return Choice::Both;
  }
}

constexpr double kInfD = std::numeric_limits<double>::infinity();

// Fast path for the common arithmetic ops on finite operands. Bit-identical to applyOp
// (interval.cpp): the same IEEE operations and the same one-ulp outward steps; anything else
// (infinite or NaN bounds, other ops) goes through applyOp.
inline double nextUp1(double x) {
  if (!(x < kInfD)) return x;
  if (x == 0.0) return std::numeric_limits<double>::denorm_min();
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = x > 0.0 ? bits + 1 : bits - 1;
  std::memcpy(&x, &bits, sizeof bits);
  return x;
}
inline double up1(double x) { return nextUp1(x); }
inline double down1(double x) { return -nextUp1(-x); }
inline bool finiteIv(const Interval& a) { return std::fabs(a.lo) < kInfD && std::fabs(a.hi) < kInfD; }

// Returns false when the op is not handled here (the caller then uses applyOp).
inline bool fastOp(Op op, const Interval& a, const Interval& b, double imm, Interval& r) {
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
      if (!finiteIv(a) || !finiteIv(b)) return false;
      r = Interval(down1(a.lo + b.lo), up1(a.hi + b.hi));
      return true;
    case Op::Sub:
      if (!finiteIv(a) || !finiteIv(b)) return false;
      r = Interval(down1(a.lo - b.hi), up1(a.hi - b.lo));
      return true;
    case Op::Mul: {
      if (!finiteIv(a) || !finiteIv(b)) return false;
      const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
      r = Interval(down1(*std::min_element(p, p + 4)), up1(*std::max_element(p, p + 4)));
      return true;
    }
    case Op::Min:
      if (!finiteIv(a) || !finiteIv(b)) return false;
      r = Interval(std::min(a.lo, b.lo), std::min(a.hi, b.hi));
      return true;
    case Op::Max:
      if (!finiteIv(a) || !finiteIv(b)) return false;
      r = Interval(std::max(a.lo, b.lo), std::max(a.hi, b.hi));
      return true;
    default:
      return false;
  }
}

}  // namespace

Interval IntervalEvaluator::eval(const Tape& tape, const Interval* box) {
  // Uniforms are written once per root tape; pruned tapes share the root's register layout.
  if (boundId_ != tape.root()->id() || regs_.size() < tape.numRegs()) {
    regs_.assign(tape.numRegs(), Interval());
    const auto& u = tape.uniforms();
    // A constant folded to NaN (e.g. fmod(1, 0)) becomes everything(), the NaN marker.
    for (size_t i = 0; i < u.size(); ++i) regs_[i] = std::isnan(u[i]) ? Interval::everything() : Interval(u[i]);
    boundId_ = tape.root()->id();
  }
  Interval* r = regs_.data();
  const uint32_t v0 = tape.varReg(0);
  for (uint32_t i = 0; i < tape.numVars(); ++i) r[v0 + i] = box[i];

  const auto& code = tape.code();
  choices_.assign(code.size(), Choice::Both);  // keeps capacity: no allocation after warm-up
  for (size_t k = 0; k < code.size(); ++k) {
    const Instr& ins = code[k];
    if (ins.op == Op::Extremum) {
      // Not a choice: an extremum stays in pruned tapes. Sound bounds from a short
      // branch-and-bound over the hidden domain (ExtremumSolver::bound).
      const ExtremumEntry& e = tape.extrema()[ins.a];
      xbuf_.resize(e.inputRegs.size());
      for (size_t i = 0; i < e.inputRegs.size(); ++i) xbuf_[i] = r[e.inputRegs[i]];
      r[ins.out] = extrema_.get(tape, ins.a).bound(xbuf_.data(), extremumSignOnly_);
      continue;
    }
    if (ins.op == Op::Min || ins.op == Op::Max || ins.op == Op::Select) {
      const Choice ch = decide(ins.op, r[ins.a], r[ins.b]);
      choices_[k] = ch;
      if (ch != Choice::Both) {
        const bool sel = ins.op == Op::Select;
        r[ins.out] = ch == Choice::KeepA ? r[sel ? ins.b : ins.a] : r[sel ? ins.c : ins.b];
        continue;
      }
    }
    if (ins.a == ins.b && ins.op == Op::Mul) {
      // x * x is x^2 bit for bit (powInt squares the same way), and x^2 is tighter than x * y.
      r[ins.out] = applyOp(Op::PowI, r[ins.a], Interval(), Interval(), 2.0);
      continue;
    }
    Interval v;
    if (fastOp(ins.op, r[ins.a], r[ins.b], ins.imm, v)) r[ins.out] = v;
    else r[ins.out] = applyOp(ins.op, r[ins.a], r[ins.b], r[ins.c], ins.imm);
  }
  return r[tape.resultReg()];
}

}  // namespace frep
