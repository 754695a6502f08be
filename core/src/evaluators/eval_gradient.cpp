// Forward-mode gradient evaluators: a value register file plus one derivative row per register
// (d reg / d x[j] for every coordinate j), for one point (GradientEvaluator) or for a batch of
// points in lanes (BatchGradientEvaluator, the same formulas lane by lane). Conventions match
// the symbolic derivative() in expr.cpp: piecewise ops take the derivative of the branch applyOp
// takes, and a zero input derivative contributes nothing (so an infinite partial times a
// constant input stays 0).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/expressions/sin_cos.h"
#include "frep/extremum/extremum.h"
#include "isa_clones.h"

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

// ---- batches of points ---------------------------------------------------------------------

namespace {

constexpr size_t kLanes = BatchGradientEvaluator::kBatch;

// Partials are kept along x[1..3] only: row j of register r is der[(r * 3 + j) * kLanes].
inline double* row(double* der, uint32_t reg, uint32_t j) { return der + (size_t(reg) * 3 + j) * kLanes; }

// An op with one partial per input, p[l] (and q[l] for the second input): the output rows as
// GradientEvaluator writes them (term of each input row). Reads lane l of the input rows before
// writing lane l of the output row, so the output may alias an input.
inline void chain1(double* der, const Instr& ins, uint32_t nd, const double* p, size_t n) {
  for (uint32_t j = 0; j < nd; ++j) {
    const double* da = row(der, ins.a, j);
    double* o = row(der, ins.out, j);
    for (size_t l = 0; l < n; ++l) o[l] = term(p[l], da[l]);
  }
}
inline void chain2(double* der, const Instr& ins, uint32_t nd, const double* p, const double* q, size_t n) {
  for (uint32_t j = 0; j < nd; ++j) {
    const double *da = row(der, ins.a, j), *db = row(der, ins.b, j);
    double* o = row(der, ins.out, j);
    for (size_t l = 0; l < n; ++l) o[l] = term(p[l], da[l]) + term(q[l], db[l]);
  }
}
// Min/max/select: lane l's row is that of the input the value took (pick[l]: the second, b).
inline void pickRows(double* der, uint32_t out, uint32_t first, uint32_t second, uint32_t nd, const char* pick, size_t n) {
  for (uint32_t j = 0; j < nd; ++j) {
    const double *x = row(der, first, j), *y = row(der, second, j);
    double* o = row(der, out, j);
    for (size_t l = 0; l < n; ++l) o[l] = pick[l] ? y[l] : x[l];
  }
}

// The tape over n lanes (values reg-major, val[r * kLanes + l]). The common ops run as loops
// over lanes; every other op runs GradientEvaluator's code lane by lane. Each op computes its
// value and partials from its inputs first and writes its output rows after (out may alias an
// input). p, q, t, pick: scratch of kLanes.
FREP_CLONES void runGradientTape(const Instr* code, size_t ninstr, double* val, double* der, uint32_t nd, size_t n,
                                 double* p, double* q, double* t, char* pick) {
  for (size_t k = 0; k < ninstr; ++k) {
    const Instr& ins = code[k];
    const double* A = val + size_t(ins.a) * kLanes;
    const double* B = val + size_t(ins.b) * kLanes;
    const double* C = val + size_t(ins.c) * kLanes;
    double* O = val + size_t(ins.out) * kLanes;
    switch (ins.op) {
      case Op::Add:
        for (size_t l = 0; l < n; ++l) p[l] = 1.0;
        chain2(der, ins, nd, p, p, n);
        for (size_t l = 0; l < n; ++l) O[l] = A[l] + B[l];
        continue;
      case Op::Sub:
        for (size_t l = 0; l < n; ++l) p[l] = 1.0, q[l] = -1.0;
        chain2(der, ins, nd, p, q, n);
        for (size_t l = 0; l < n; ++l) O[l] = A[l] - B[l];
        continue;
      case Op::Mul:
        chain2(der, ins, nd, B, A, n);  // d(ab) = b da + a db
        for (size_t l = 0; l < n; ++l) O[l] = A[l] * B[l];
        continue;
      case Op::Div:
        for (size_t l = 0; l < n; ++l) p[l] = 1.0 / B[l], q[l] = -A[l] / (B[l] * B[l]);
        chain2(der, ins, nd, p, q, n);
        for (size_t l = 0; l < n; ++l) O[l] = A[l] / B[l];
        continue;
      case Op::Neg:
        for (size_t l = 0; l < n; ++l) p[l] = -1.0;
        chain1(der, ins, nd, p, n);
        for (size_t l = 0; l < n; ++l) O[l] = -A[l];
        continue;
      case Op::Abs:
        for (size_t l = 0; l < n; ++l) p[l] = A[l] > 0.0 ? 1.0 : (A[l] < 0.0 ? -1.0 : 0.0);
        chain1(der, ins, nd, p, n);
        for (size_t l = 0; l < n; ++l) O[l] = std::fabs(A[l]);
        continue;
      case Op::Sqrt:
        for (size_t l = 0; l < n; ++l) t[l] = A[l] > 0.0 ? std::sqrt(A[l]) : 0.0;
        for (size_t l = 0; l < n; ++l) p[l] = A[l] > 0.0 ? 1.0 / (2.0 * t[l]) : 0.0;
        chain1(der, ins, nd, p, n);
        for (size_t l = 0; l < n; ++l) O[l] = t[l];
        continue;
      case Op::Sin:
      case Op::Cos: {
        // sin and cos of every lane (t, p), as ownSin/ownCos give them; d sin = cos, d cos = -sin.
        bool inRange = true;
        for (size_t l = 0; l < n; ++l) inRange &= ownTrigInRange(A[l]);
        if (inRange)
          for (size_t l = 0; l < n; ++l) ownSinCosInRange(A[l], t[l], p[l]);
        else
          for (size_t l = 0; l < n; ++l) ownSinCos(A[l], t[l], p[l]);
        if (ins.op == Op::Cos)
          for (size_t l = 0; l < n; ++l) std::swap(t[l], p[l]), p[l] = -p[l];
        chain1(der, ins, nd, p, n);
        for (size_t l = 0; l < n; ++l) O[l] = t[l];
        continue;
      }
      case Op::Min:
        for (size_t l = 0; l < n; ++l) pick[l] = B[l] < A[l];
        pickRows(der, ins.out, ins.a, ins.b, nd, pick, n);
        for (size_t l = 0; l < n; ++l) O[l] = pick[l] ? B[l] : A[l];
        continue;
      case Op::Max:
        for (size_t l = 0; l < n; ++l) pick[l] = B[l] > A[l];
        pickRows(der, ins.out, ins.a, ins.b, nd, pick, n);
        for (size_t l = 0; l < n; ++l) O[l] = pick[l] ? B[l] : A[l];
        continue;
      case Op::Select:
        for (size_t l = 0; l < n; ++l) pick[l] = A[l] != 0.0;
        pickRows(der, ins.out, ins.c, ins.b, nd, pick, n);
        for (size_t l = 0; l < n; ++l) O[l] = pick[l] ? B[l] : C[l];
        continue;
      case Op::Copy:
        for (uint32_t j = 0; j < nd; ++j) {
          const double* da = row(der, ins.a, j);
          double* o = row(der, ins.out, j);
          if (o != da) std::copy(da, da + n, o);
        }
        if (O != A) std::copy(A, A + n, O);
        continue;
      default:
        break;
    }
    // Any other op: GradientEvaluator::eval's step for each lane.
    const bool constant = isPiecewiseConstant(ins.op), unary = opArity(ins.op) == 1;
    for (size_t l = 0; l < n; ++l) {
      const double a = A[l], b = B[l], c = C[l];
      const double value = applyOp(ins.op, a, b, c, ins.imm);
      const Partials pt = constant || ins.op == Op::Frac ? Partials{} : partials(ins.op, a, b, value, ins.imm);
      for (uint32_t j = 0; j < nd; ++j) {
        double* o = row(der, ins.out, j);
        const double da = row(der, ins.a, j)[l], db = row(der, ins.b, j)[l];
        o[l] = constant ? 0.0 : ins.op == Op::Frac ? da : unary ? term(pt.da, da) : term(pt.da, da) + term(pt.db, db);
      }
      O[l] = value;
    }
  }
}

}  // namespace

void BatchGradientEvaluator::bind(const Tape& tape) {
  const size_t nr = tape.numRegs();
  if (boundId_ == tape.root()->id() && val_.size() >= nr * kBatch) return;
  // Uniform rows hold their value in every lane and partials 0; coordinate rows unit partials.
  // Temporaries are always written before they are read.
  val_.assign(nr * kBatch, 0.0);
  der_.assign(nr * 3 * kBatch, 0.0);
  const auto& u = tape.uniforms();
  for (size_t r = 0; r < u.size(); ++r) std::fill_n(val_.data() + r * kBatch, kBatch, u[r]);
  for (uint32_t i = 0; i < std::min(tape.numVars(), 3u); ++i) std::fill_n(row(der_.data(), tape.varReg(i), i), kBatch, 1.0);
  boundId_ = tape.root()->id();
  numUniformsBound_ = tape.numUniforms();
}

void BatchGradientEvaluator::reserve(const Tape& tape) { bind(tape); }

double* BatchGradientEvaluator::in(uint32_t var) {
  // Vars follow the uniforms in every tape derived from the same root.
  return val_.data() + size_t(numUniformsBound_ + var) * kBatch;
}

void BatchGradientEvaluator::eval(const Tape& tape, size_t count) {
  bind(tape);
  if (count > kBatch) throw std::invalid_argument("BatchGradientEvaluator: more than kBatch points");
  const uint32_t nv = tape.numVars(), nd = std::min(nv, 3u);
  double* value = out_.data();
  if (tape.hasExtrema() || !tape.fields().empty()) {
    x_.resize(nv);
    g_.resize(nv);
    for (size_t l = 0; l < count; ++l) {
      for (uint32_t i = 0; i < nv; ++i) x_[i] = in(i)[l];
      std::fill(g_.begin(), g_.end(), 0.0);
      value[l] = scalar_.eval(tape, x_.data(), g_.data());
      for (uint32_t j = 0; j < 3; ++j) out_[(j + 1) * kBatch + l] = j < nd ? g_[j] : 0.0;
    }
    return;
  }
  // Lanes past count are computed and ignored (whole vectors; the scratch follows the outputs).
  const size_t n = std::min(kBatch, (count + 7) & ~size_t(7));
  runGradientTape(tape.code().data(), tape.code().size(), val_.data(), der_.data(), nd, n, scratch_.data(),
                  scratch_.data() + kBatch, scratch_.data() + 2 * kBatch, pick_.data());
  const uint32_t r = tape.resultReg();
  std::copy_n(val_.data() + size_t(r) * kBatch, count, value);
  for (uint32_t j = 0; j < 3; ++j) {
    double* o = out_.data() + (j + 1) * kBatch;
    if (j < nd)
      std::copy_n(row(der_.data(), r, j), count, o);
    else
      std::fill_n(o, count, 0.0);
  }
}

}  // namespace frep
