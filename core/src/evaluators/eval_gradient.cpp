// Forward-mode gradient evaluator: a value register file plus one derivative row per register
// (d reg / d x[j] for every coordinate j). Conventions match the symbolic derivative() in
// expr.cpp: piecewise ops take the derivative of the branch applyOp takes, and a zero input
// derivative contributes nothing (so an infinite partial times a constant input stays 0).
#include <algorithm>
#include <cmath>

#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/expressions/sin_cos.h"
#include "frep/extremum/extremum.h"

namespace frep {

namespace {

// Partial derivatives of a unary/binary op with respect to its inputs a and b.
struct Partials {
  double da = 0.0, db = 0.0;
};

Partials partials(Op op, double a, double b, double value, double imm) {
  switch (op) {
    case Op::Neg: return {-1.0};
    case Op::Abs: return {a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0)};
    case Op::Sqrt: return {a > 0.0 ? 1.0 / (2.0 * value) : 0.0};
    case Op::Exp: return {value};
    case Op::Log: return {a > kLogFloor ? 1.0 / a : 0.0};
    case Op::Log10: return {a > kLogFloor ? 1.0 / (a * std::log(10.0)) : 0.0};
    case Op::Sin: return {ownCos(a)};
    case Op::Cos: return {-ownSin(a)};
    case Op::Tan: return {1.0 + value * value};
    case Op::Asin: return {std::fabs(a) < 1.0 ? 1.0 / std::sqrt(1.0 - a * a) : 0.0};
    case Op::Acos: return {std::fabs(a) < 1.0 ? -1.0 / std::sqrt(1.0 - a * a) : 0.0};
    case Op::Atan: return {1.0 / (1.0 + a * a)};
    case Op::Sinh: return {std::cosh(a)};
    case Op::Cosh: return {std::sinh(a)};
    case Op::Tanh: return {1.0 - value * value};
    case Op::Frac: case Op::Copy: return {1.0};
    case Op::PowI: return {imm * applyOp(Op::PowI, a, 0.0, 0.0, imm - 1.0)};
    case Op::Add: return {1.0, 1.0};
    case Op::Sub: return {1.0, -1.0};
    case Op::Mul: return {b, a};
    case Op::Div: return {1.0 / b, -a / (b * b)};
    // d/da a^b = b a^(b-1) (also right for a <= 0 and integer b); d/db = a^b log(a), with
    // log's floor so that 0^b (b > 0) gets the limit 0.
    case Op::Pow: return {b * std::pow(a, b - 1.0), value * applyOp(Op::Log, a)};
    case Op::Atan2: {
      double r2 = a * a + b * b;
      return {b / r2, -a / r2};
    }
    case Op::Fmod: return {1.0, -std::trunc(a / b)};
    case Op::RAnd: case Op::ROr: {
      Partials p{};
      rFunctionPartials(op == Op::ROr, a, b, imm, p.da, p.db);
      return p;
    }
    default: return {};  // floor/ceil/trunc/comparisons/logic: piecewise constant
  }
}

bool isPiecewiseConstant(Op op) {
  switch (op) {
    case Op::Floor: case Op::Ceil: case Op::Trunc: case Op::Not: case Op::Lt: case Op::Le:
    case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: case Op::And: case Op::Or:
      return true;
    default:
      return false;
  }
}

inline double term(double partial, double d) { return d == 0.0 ? 0.0 : partial * d; }

}  // namespace

double GradientEvaluator::eval(const Tape& tape, const double* x, double* grad) {
  const uint32_t nv = tape.numVars();
  const size_t nr = tape.numRegs();
  if (boundId_ != tape.root()->id() || val_.size() < nr || der_.size() < nr * nv) {
    // Uniform rows are constant (derivative 0); coordinate rows are unit vectors. Temporaries
    // are always written before they are read.
    val_.assign(nr, 0.0);
    der_.assign(nr * nv, 0.0);
    const auto& u = tape.uniforms();
    std::copy(u.begin(), u.end(), val_.begin());
    for (uint32_t i = 0; i < nv; ++i) der_[size_t(tape.varReg(i)) * nv + i] = 1.0;
    boundId_ = tape.root()->id();
  }
  double* v = val_.data();
  double* d = der_.data();
  for (uint32_t i = 0; i < nv; ++i) v[tape.varReg(i)] = x[i];

  for (const Instr& ins : tape.code()) {
    if (ins.op == Op::Extremum) {
      // Danskin's theorem: d/dx max_u g(X(x), u) = sum_k dg/dX_k (X, u*) dX_k/dx.
      const ExtremumEntry& e = tape.extrema()[ins.a];
      const size_t nin = e.inputRegs.size();
      xbuf_.resize(nin);
      gbuf_.resize(nin);
      for (size_t k = 0; k < nin; ++k) xbuf_[k] = v[e.inputRegs[k]];
      const double value = extrema_.get(tape, ins.a).gradient(xbuf_.data(), gbuf_.data());
      row_.assign(nv, 0.0);
      for (size_t k = 0; k < nin; ++k) {
        const double* dk = d + size_t(e.inputRegs[k]) * nv;
        for (uint32_t j = 0; j < nv; ++j) row_[j] += term(gbuf_[k], dk[j]);
      }
      std::copy(row_.begin(), row_.end(), d + size_t(ins.out) * nv);
      v[ins.out] = value;
      continue;
    }
    if (ins.op == Op::Field) {
      // Chain rule through the object's own partials.
      const double p[3] = {v[ins.a], v[ins.b], v[ins.c]};
      double g[3];
      const double value = tape.field(ins).gradient(p, g);
      const uint32_t in[3] = {ins.a, ins.b, ins.c};
      row_.assign(nv, 0.0);
      for (int k = 0; k < 3; ++k) {
        const double* dk = d + size_t(in[k]) * nv;
        for (uint32_t j = 0; j < nv; ++j) row_[j] += term(g[k], dk[j]);
      }
      std::copy(row_.begin(), row_.end(), d + size_t(ins.out) * nv);
      v[ins.out] = value;
      continue;
    }
    // Inputs are read before the output is written: out may alias a, b or c.
    const double a = v[ins.a], b = v[ins.b], c = v[ins.c];
    const double value = applyOp(ins.op, a, b, c, ins.imm);
    double* dout = d + size_t(ins.out) * nv;
    const double* da = d + size_t(ins.a) * nv;
    const double* db = d + size_t(ins.b) * nv;
    // Ops that pass one input's derivative through (min/max/select/copy/frac) copy a row.
    const double* passRow = nullptr;
    switch (ins.op) {
      case Op::Min: passRow = b < a ? db : da; break;
      case Op::Max: passRow = b > a ? db : da; break;
      case Op::Select: passRow = a != 0.0 ? db : d + size_t(ins.c) * nv; break;
      case Op::Copy: case Op::Frac: passRow = da; break;
      default: break;
    }
    if (isPiecewiseConstant(ins.op)) {
      std::fill(dout, dout + nv, 0.0);  // even where the input's derivative is inf or NaN
    } else if (passRow) {
      if (passRow != dout) std::copy(passRow, passRow + nv, dout);
    } else {
      const Partials p = partials(ins.op, a, b, value, ins.imm);
      // Element j of every input row is read before element j of the output row is written,
      // so in-place updates are safe when out aliases an input.
      if (opArity(ins.op) == 1)
        for (uint32_t j = 0; j < nv; ++j) dout[j] = term(p.da, da[j]);
      else
        for (uint32_t j = 0; j < nv; ++j) dout[j] = term(p.da, da[j]) + term(p.db, db[j]);
    }
    v[ins.out] = value;
  }
  const double* dres = d + size_t(tape.resultReg()) * nv;
  std::copy(dres, dres + nv, grad);
  return v[tape.resultReg()];
}

}  // namespace frep
