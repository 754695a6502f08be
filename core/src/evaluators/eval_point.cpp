// Point evaluator: the double-precision reference walk of a tape.
#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"

namespace frep {

double PointEvaluator::eval(const Tape& tape, const double* x) {
  if (boundId_ != tape.root()->id() || regs_.size() < tape.numRegs()) {
    regs_.assign(tape.numRegs(), 0.0);
    const auto& u = tape.uniforms();
    for (size_t i = 0; i < u.size(); ++i) regs_[i] = u[i];
    boundId_ = tape.root()->id();
  }
  double* r = regs_.data();
  const uint32_t v0 = tape.varReg(0);
  for (uint32_t i = 0; i < tape.numVars(); ++i) r[v0 + i] = x[i];
  if (!tape.hasExtrema() && tape.fields().empty() && !domain_) {
    for (const Instr& ins : tape.code()) r[ins.out] = applyOp(ins.op, r[ins.a], r[ins.b], r[ins.c], ins.imm);
    return r[tape.resultReg()];
  }
  DomainError kind;
  params_.resize(tape.extrema().size());
  for (auto& p : params_) p.clear();
  for (const Instr& ins : tape.code()) {
    if (ins.op == Op::Extremum) {
      const ExtremumEntry& e = tape.extrema()[ins.a];
      xbuf_.resize(e.inputRegs.size());
      for (size_t k = 0; k < e.inputRegs.size(); ++k) xbuf_[k] = r[e.inputRegs[k]];
      ExtremumSolver& solver = extrema_.get(tape, ins.a);
      const double* warm = nullptr;
      if (warm_ && ins.a < warm_->size() && (*warm_)[ins.a].size() == solver.spec().numParams())
        warm = (*warm_)[ins.a].data();
      ExtremumResult res = solver.solve(xbuf_.data(), warm);
      r[ins.out] = res.value;
      params_[ins.a] = std::move(res.t);
      continue;
    }
    if (ins.op == Op::Field) {
      const double p[3] = {r[ins.a], r[ins.b], r[ins.c]};
      r[ins.out] = tape.field(ins).value(p);
      continue;
    }
    if (domain_ && isDomainError(ins.op, r[ins.a], r[ins.b], kind)) ++domain_->n[size_t(kind)];
    r[ins.out] = applyOp(ins.op, r[ins.a], r[ins.b], r[ins.c], ins.imm);
  }
  return r[tape.resultReg()];
}

}  // namespace frep
