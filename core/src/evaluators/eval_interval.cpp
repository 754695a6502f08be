// Interval evaluator: one walk of the tape over a box, recording for each min/max/select
// whether the box decides it, so the tape can be pruned for everything inside the box.
#include <cmath>
#include <cstdint>

#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"
#include "evaluators/interval_fast.h"

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
      Interval b = extrema_.get(tape, ins.a).bound(xbuf_.data(), extremumSignOnly_, extremumBudgetOnly_);
      // The bound encloses the true extremum; a certified search returns a value up to its
      // tolerance below a maximum (above a minimum): widen by that much, so that a sign the
      // interval decides is also the sign of every value the point evaluators compute.
      if (e.spec->method == ExtremumMethod::BranchAndBound) {
        if (e.spec->kind == ExtremumKind::Max) b.lo -= e.spec->tolerance;
        else b.hi += e.spec->tolerance;
      } else {
        // The grid search's value is a real body value, so it can fall short of a maximum by
        // any amount the grid misses (L * delta for an L-Lipschitz body, L unknown here): only
        // the other side decides signs, or a brick whose box said "inside" would disagree with
        // its neighbour's search at the same point and the mesh would open at the seam.
        if (e.spec->kind == ExtremumKind::Max) b.lo = -INFINITY;
        else b.hi = INFINITY;
      }
      r[ins.out] = b;
      continue;
    }
    if (ins.op == Op::Field) {
      const Interval in[3] = {r[ins.a], r[ins.b], r[ins.c]};
      r[ins.out] = tape.field(ins).bound(in);
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
    if (detail::fastOp(ins.op, r[ins.a], r[ins.b], ins.imm, v)) r[ins.out] = v;
    else r[ins.out] = applyOp(ins.op, r[ins.a], r[ins.b], r[ins.c], ins.imm);
  }
  return r[tape.resultReg()];
}

}  // namespace frep
