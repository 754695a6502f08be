// Batch evaluator: one pass over the tape per batch of points, each instruction (or fused short
// chain, see runFused) a tight loop over structure-of-arrays lanes that the compiler vectorises
// (arithmetic, min/max, sqrt, comparisons, select, sin/cos of sin_cos.h); other transcendentals
// call libm per lane. The kernel is compiled for several ISA levels (target_clones) and picked at
// run time; -ffp-contract=off keeps every clone bit-identical to the others and to the point
// evaluator.
#include <algorithm>
#include <cmath>

#include "frep/evaluators/eval.h"
#include "frep/expressions/pow_int.h"
#include "frep/expressions/sin_cos.h"
#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"
#include "isa_clones.h"

namespace frep {

namespace {

// Lanes (< n) whose argument is outside the own sin/cos range (sin_cos.h), NaN included.
inline size_t lanesOutOfTrigRange(const double* a, size_t n) {
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i) bad += !(std::fabs(a[i]) <= kOwnTrigLimit);
  return bad;
}
inline size_t lanesOutOfTrigRange(const float* a, size_t n) {
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i) bad += !(std::fabs(a[i]) <= kOwnTrigLimitFloat);
  return bad;
}

// Sin or Cos of every lane, or both (sinOut and cosOut non-null) when the tape's sinCosPlan
// pairs them: ownSinCos in double, ownSinCosFloat in float (sin_cos.h). Chunks through a local
// buffer: an output may be the input register. A batch with a lane out of range takes the scalar
// path of the same functions (same bits on the other lanes).
inline void trigLane(double x, double& s, double& c) { ownSinCosInRange(x, s, c); }
inline void trigLane(float x, float& s, float& c) { ownSinCosInRangeFloat(x, s, c); }
inline void trigLaneChecked(double x, double& s, double& c) { ownSinCos(x, s, c); }
inline void trigLaneChecked(float x, float& s, float& c) { ownSinCosFloat(x, s, c); }

template <typename T>
constexpr size_t kTrigChunk = sizeof(T) == 8 ? 32 : 64;

template <typename T, size_t C>
inline __attribute__((always_inline)) void trigChunk(const T* a, T* sinOut, T* cosOut, size_t i0) {
  T sv[C], cv[C];
  for (size_t j = 0; j < C; ++j) trigLane(a[j], sv[j], cv[j]);
  if (sinOut)
    for (size_t j = 0; j < C; ++j) sinOut[i0 + j] = sv[j];
  if (cosOut)
    for (size_t j = 0; j < C; ++j) cosOut[i0 + j] = cv[j];
}

template <typename T>
FREP_CLONES void runTrig(const T* a, T* sinOut, T* cosOut, size_t n) {
  if (lanesOutOfTrigRange(a, n)) {
    for (size_t i = 0; i < n; ++i) {
      T sv, cv;
      trigLaneChecked(a[i], sv, cv);
      if (sinOut) sinOut[i] = sv;
      if (cosOut) cosOut[i] = cv;
    }
    return;
  }
  // Chunks of several vectors (C lanes), so that the polynomials' independent chains overlap;
  // n is a multiple of 8, the rest goes by 8.
  size_t i0 = 0;
  for (; i0 + kTrigChunk<T> <= n; i0 += kTrigChunk<T>) trigChunk<T, kTrigChunk<T>>(a + i0, sinOut, cosOut, i0);
  for (; i0 < n; i0 += 8) trigChunk<T, 8>(a + i0, sinOut, cosOut, i0);
}

// A Sin or Cos: alone, or the first of a pair of the tape's sinCosPlan, which writes both
// outputs (the partner's register is free until the partner, see planSinCos); the second of a
// pair has nothing left to do.
template <typename T>
void runSinOrCos(const Instr& ins, const uint32_t* plan, T* regs, size_t n) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  const uint32_t partner = plan ? *plan : Tape::kNoSinCos;
  if (partner == Tape::kSinCosDone) return;
  const T* a = regs + size_t(ins.a) * B;
  T* own = regs + size_t(ins.out) * B;
  T* other = partner == Tape::kNoSinCos ? nullptr : regs + size_t(partner) * B;
  if (ins.op == Op::Sin) runTrig(a, own, other, n);
  else runTrig(a, other, own, n);
}

// Counts the lanes (< count) where an instruction hits a domain error; runs before the
// instruction writes its output (which may alias an input).
template <typename T>
void countDomainErrors(const Instr& ins, const T* a, const T* b, size_t count, DomainCounts& dom) {
  uint64_t hits = 0;
  DomainError kind;
  switch (ins.op) {
    case Op::Sqrt: case Op::Log: case Op::Log10: case Op::Asin: case Op::Acos: case Op::Div:
    case Op::Pow: case Op::Fmod:
      for (size_t i = 0; i < count; ++i) hits += isDomainError(ins.op, double(a[i]), double(b[i]), kind);
      if (hits) dom.n[size_t(kind)] += hits;  // kind is set by every call
      break;
    default:
      break;
  }
}

// An Op::Field instruction: the object evaluates all lanes at once in double (its output may
// alias an input, so through a side buffer).
template <typename T>
void runField(const FieldFunction& fn, const Instr& ins, T* regs, size_t n, bool signsOnly = false) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  thread_local std::vector<double> buf;
  buf.resize(4 * B);
  double *u = buf.data(), *v = u + B, *w = v + B, *out = w + B;
  const T* a = regs + size_t(ins.a) * B;
  const T* b = regs + size_t(ins.b) * B;
  const T* c = regs + size_t(ins.c) * B;
  for (size_t i = 0; i < n; ++i) u[i] = double(a[i]), v[i] = double(b[i]), w[i] = double(c[i]);
  if (signsOnly)
    fn.signs(u, v, w, out, n);
  else
    fn.values(u, v, w, out, n);
  T* o = regs + size_t(ins.out) * B;
  for (size_t i = 0; i < n; ++i) o[i] = T(out[i]);
}

// A binary op over the lanes with a uniform operand (a constant: its register holds one value in
// every lane), read once as a scalar: a load less per lane, and the constants' registers stay
// out of the cache. Same operations on the same values: the same bits (a finite constant leaves
// no choice of which NaN propagates). Returns false when neither operand is uniform.
template <typename T, typename F>
inline __attribute__((always_inline)) bool uniformLoop(const T* a, const T* b, T* __restrict o, size_t n,
                                                       bool aUniform, bool bUniform, F f) {
  if (bUniform) {
    const T y = b[0];
    for (size_t i = 0; i < n; ++i) o[i] = f(a[i], y);
  } else if (aUniform) {
    const T x = a[0];
    for (size_t i = 0; i < n; ++i) o[i] = f(x, b[i]);
  } else {
    return false;
  }
  return true;
}

// Fused in-place chains (tape specialisation). The tape's register allocator writes
// "t = x - c; t = t^2; t = d - t" into one register, so each intermediate value is overwritten by
// the next instruction and read by nothing else: one loop computes the chain with the same
// operations in the same order (same bits), without storing and reloading the intermediates.
// Returns how many instructions it ran (0: no pattern here).
inline bool isSquare(const Instr& i) { return i.op == Op::PowI && i.imm == 2.0; }
inline bool squaresInPlace(const Instr& next, uint32_t r) { return isSquare(next) && next.a == r && next.out == r; }
// next = u - r or next = r - u (in place on r, u another register)
inline int subtractsInPlace(const Instr& next, uint32_t r) {
  if (next.op != Op::Sub || next.out != r) return 0;
  if (next.b == r && next.a != r) return 1;  // u - r
  if (next.a == r && next.b != r) return 2;  // r - u
  return 0;
}

// Whether instruction k + 1 is the last reader of register q written at k: it overwrites q
// itself, or k + 2 overwrites q without reading it.
inline bool lastReaderIsNext(const Instr* code, size_t k, size_t ninstr, uint32_t q) {
  const Instr& next = code[k + 1];
  if (next.out == q) return true;
  if (k + 2 >= ninstr) return false;
  const Instr& after = code[k + 2];
  const int ar = opArity(after.op);
  return after.out == q && after.op != Op::Extremum && after.op != Op::Field && !(ar > 0 && after.a == q) &&
         !(ar > 1 && after.b == q) && !(ar > 2 && after.c == q);
}

// t = a op b (+ - *, registers) then min or max of t with another register, t read by nothing
// else (CSG's "max(holes, c - ...)" chains): one loop, the operands in the tape's order.
template <typename T>
inline __attribute__((always_inline)) size_t runIntoMinMax(const Instr* code, size_t k, size_t ninstr, T* regs,
                                                           size_t n) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  const Instr &i0 = code[k], &i1 = code[k + 1];
  const uint32_t q = i0.out;
  if ((i1.op != Op::Min && i1.op != Op::Max) || (i1.a == q) == (i1.b == q) || !lastReaderIsNext(code, k, ninstr, q))
    return 0;
  auto reg = [&](uint32_t r) { return regs + size_t(r) * B; };
  const T *a = reg(i0.a), *b = reg(i0.b), *p = reg(i1.a == q ? i1.b : i1.a);
  T* __restrict o = reg(i1.out);
  const bool tFirst = i1.a == q;
  auto run = [&](auto f) {
    // min: y < x ? y : x, max: y > x ? y : x, with (x, y) = (i1.a, i1.b)
    if (i1.op == Op::Min && tFirst) {
      for (size_t i = 0; i < n; ++i) { const T x = f(a[i], b[i]), y = p[i]; o[i] = y < x ? y : x; }
    } else if (i1.op == Op::Min) {
      for (size_t i = 0; i < n; ++i) { const T x = p[i], y = f(a[i], b[i]); o[i] = y < x ? y : x; }
    } else if (tFirst) {
      for (size_t i = 0; i < n; ++i) { const T x = f(a[i], b[i]), y = p[i]; o[i] = y > x ? y : x; }
    } else {
      for (size_t i = 0; i < n; ++i) { const T x = p[i], y = f(a[i], b[i]); o[i] = y > x ? y : x; }
    }
  };
  if (i0.op == Op::Add) run([](T u, T v) { return u + v; });
  else if (i0.op == Op::Sub) run([](T u, T v) { return u - v; });
  else run([](T u, T v) { return u * v; });
  return 2;
}

template <typename T>
inline __attribute__((always_inline)) size_t runFused(const Instr* code, size_t k, size_t ninstr, T* regs, size_t n,
                                                      uint32_t numUniforms) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  const Instr& i0 = code[k];
  const uint32_t r = i0.out;
  auto reg = [&](uint32_t q) { return regs + size_t(q) * B; };
  T* __restrict o = reg(r);
  const bool aUniform = i0.a < numUniforms, bUniform = i0.b < numUniforms;
  if ((i0.op == Op::Add || i0.op == Op::Sub) && aUniform != bUniform && (aUniform ? i0.b : i0.a) != r &&
      k + 1 < ninstr && squaresInPlace(code[k + 1], r)) {
    // (x +- c)^2 or (c +- x)^2, then maybe d - that or that - d
    const T* x = reg(aUniform ? i0.b : i0.a);
    const T c = reg(aUniform ? i0.a : i0.b)[0];
    const int sub = k + 2 < ninstr ? subtractsInPlace(code[k + 2], r) : 0;
    const uint32_t dq = sub == 1 ? code[k + 2].a : code[k + 2].b;
    const bool three = sub && dq < numUniforms;
    const T d = three ? reg(dq)[0] : T(0);
    auto chain = [&](auto first) {
      if (three && sub == 1) {
        for (size_t i = 0; i < n; ++i) { const T t = first(x[i]); o[i] = d - t * t; }
      } else if (three) {
        for (size_t i = 0; i < n; ++i) { const T t = first(x[i]); o[i] = t * t - d; }
      } else {
        for (size_t i = 0; i < n; ++i) { const T t = first(x[i]); o[i] = t * t; }
      }
    };
    // the operands in the tape's order
    if (i0.op == Op::Add && aUniform) chain([c](T v) { return c + v; });
    else if (i0.op == Op::Add) chain([c](T v) { return v + c; });
    else if (aUniform) chain([c](T v) { return c - v; });
    else chain([c](T v) { return v - c; });
    return three ? 3 : 2;
  }
  if (isSquare(i0) && i0.a != r && k + 1 < ninstr) {
    // x^2 then u - that or that - u (u a register or a constant), the square read by nothing
    // else: in place, or into another register when the square's dies there
    const Instr& next = code[k + 1];
    if (next.op != Op::Sub || (next.a == r) == (next.b == r) || !lastReaderIsNext(code, k, ninstr, r)) return 0;
    const bool uFirst = next.b == r;  // u - x^2
    const T* x = reg(i0.a);
    const uint32_t uq = uFirst ? next.a : next.b;
    const T* u = reg(uq);
    T* __restrict out = reg(next.out);
    if (uq < numUniforms) {
      const T uv = u[0];
      if (uFirst) for (size_t i = 0; i < n; ++i) out[i] = uv - x[i] * x[i];
      else for (size_t i = 0; i < n; ++i) out[i] = x[i] * x[i] - uv;
    } else {
      if (uFirst) for (size_t i = 0; i < n; ++i) out[i] = u[i] - x[i] * x[i];
      else for (size_t i = 0; i < n; ++i) out[i] = x[i] * x[i] - u[i];
    }
    return 2;
  }
  if ((i0.op == Op::Add || i0.op == Op::Sub || i0.op == Op::Mul) && k + 1 < ninstr)
    return runIntoMinMax(code, k, ninstr, regs, n);
  return 0;
}

template <typename T>
FREP_CLONES void runTape(const Instr* code, const uint32_t* sinCos, size_t ninstr, T* __restrict regs, size_t n,
                         DomainCounts* dom, size_t count, const std::shared_ptr<const FieldFunction>* fields,
                         uint32_t nu) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  for (size_t k = 0; k < ninstr; ++k) {
    const Instr& ins = code[k];
    // (no fused op can hit a domain error: + - * only)
    if (const size_t fused = runFused(code, k, ninstr, regs, n, nu)) {
      k += fused - 1;
      continue;
    }
    T* __restrict o = regs + size_t(ins.out) * B;
    const T* a = regs + size_t(ins.a) * B;
    const T* b = regs + size_t(ins.b) * B;
    const T* c = regs + size_t(ins.c) * B;
    if (dom) countDomainErrors(ins, a, b, count, *dom);
#define LOOP(expr) \
  for (size_t i = 0; i < n; ++i) o[i] = (expr); \
  break
    switch (ins.op) {
      case Op::Neg: LOOP(-a[i]);
      case Op::Abs: LOOP(std::fabs(a[i]));
      // sqrt(max(a, 0)): the bits of "a > 0 ? sqrt(a) : 0" (NaN -> 0 too), without a branch
      case Op::Sqrt: LOOP(std::sqrt(a[i] > T(0) ? a[i] : T(0)));
      case Op::Exp: LOOP(std::exp(a[i]));
      case Op::Log: LOOP(T(std::log(double(a[i]) > kLogFloor ? double(a[i]) : kLogFloor)));
      case Op::Log10: LOOP(T(std::log10(double(a[i]) > kLogFloor ? double(a[i]) : kLogFloor)));
      case Op::Sin: case Op::Cos: runSinOrCos(ins, sinCos ? sinCos + k : nullptr, regs, n); break;
      case Op::Tan: LOOP(std::tan(a[i]));
      case Op::Asin: LOOP(std::asin(a[i] < T(-1) ? T(-1) : (a[i] > T(1) ? T(1) : a[i])));
      case Op::Acos: LOOP(std::acos(a[i] < T(-1) ? T(-1) : (a[i] > T(1) ? T(1) : a[i])));
      case Op::Atan: LOOP(std::atan(a[i]));
      case Op::Sinh: LOOP(std::sinh(a[i]));
      case Op::Cosh: LOOP(std::cosh(a[i]));
      case Op::Tanh: LOOP(std::tanh(a[i]));
      case Op::Floor: LOOP(std::floor(a[i]));
      case Op::Ceil: LOOP(std::ceil(a[i]));
      case Op::Trunc: LOOP(std::trunc(a[i]));
      case Op::Frac: LOOP(a[i] - std::trunc(a[i]));
      case Op::PowI: {
        const int e = static_cast<int>(ins.imm);
        if (e == 2) {
          LOOP(a[i] * a[i]);
        } else if (e == 3) {
          // same association as powInt: r = a * (a*a)
          LOOP(a[i] * (a[i] * a[i]));
        } else {
          LOOP(powInt(a[i], e));
        }
      }
      case Op::Not: LOOP(a[i] == T(0) ? T(1) : T(0));
      case Op::Copy: LOOP(a[i]);
#define BINARY(expr) \
  if (!uniformLoop(a, b, o, n, ins.a < nu, ins.b < nu, [](T x, T y) { return (expr); })) \
    for (size_t i = 0; i < n; ++i) { const T x = a[i], y = b[i]; o[i] = (expr); } \
  break
      case Op::Add: BINARY(x + y);
      case Op::Sub: BINARY(x - y);
      case Op::Mul: BINARY(x * y);
      case Op::Div: BINARY(x / y);
      case Op::Pow: LOOP(std::pow(a[i], b[i]));
      case Op::Atan2: LOOP(std::atan2(a[i], b[i]));
      case Op::Min: BINARY(y < x ? y : x);
      case Op::Max: BINARY(y > x ? y : x);
      case Op::Fmod: LOOP(std::fmod(a[i], b[i]));
      case Op::Lt: LOOP(a[i] < b[i] ? T(1) : T(0));
      case Op::Le: LOOP(a[i] <= b[i] ? T(1) : T(0));
      case Op::Gt: LOOP(a[i] > b[i] ? T(1) : T(0));
      case Op::Ge: LOOP(a[i] >= b[i] ? T(1) : T(0));
      case Op::Eq: LOOP(a[i] == b[i] ? T(1) : T(0));
      case Op::Ne: LOOP(a[i] != b[i] ? T(1) : T(0));
      case Op::And: LOOP((a[i] != T(0)) & (b[i] != T(0)) ? T(1) : T(0));
      case Op::Or: LOOP((a[i] != T(0)) | (b[i] != T(0)) ? T(1) : T(0));
      case Op::Select: LOOP(a[i] != T(0) ? b[i] : c[i]);
      case Op::Field: runField(*fields[size_t(ins.imm)], ins, regs, n); break;
      case Op::RAnd: case Op::ROr: {
        // rFunctionValue, lane by lane (same association, so the same bits as the point
        // evaluator in double)
        const T al = T(ins.imm), sg = ins.op == Op::ROr ? T(1) : T(-1);
        if (ins.imm == 0.0) {
          for (size_t i = 0; i < n; ++i) {
            T s = a[i] * a[i] + b[i] * b[i];
            T root = std::sqrt(s > T(0) ? s : T(0));
            o[i] = a[i] + b[i] + sg * root;
          }
        } else {
          for (size_t i = 0; i < n; ++i) {
            T s = a[i] * a[i] + b[i] * b[i] - T(2) * al * a[i] * b[i];
            T root = std::sqrt(s > T(0) ? s : T(0));
            o[i] = (a[i] + b[i] + sg * root) / (T(1) + al);
          }
        }
        break;
      }
      default: break;
    }
#undef LOOP
#undef BINARY
  }
}

}  // namespace

template <typename T>
void BatchEvaluator<T>::bind(const Tape& tape) {
  if (boundId_ == tape.root()->id() && regs_.size() >= size_t(tape.numRegs()) * kBatch) return;
  regs_.assign(size_t(tape.numRegs()) * kBatch, T(0));
  const auto& u = tape.uniforms();
  for (size_t r = 0; r < u.size(); ++r)
    for (size_t i = 0; i < kBatch; ++i) regs_[r * kBatch + i] = T(u[r]);
  boundId_ = tape.root()->id();
  numUniformsBound_ = tape.numUniforms();
}

template <typename T>
void BatchEvaluator<T>::reserve(const Tape& tape) {
  bind(tape);
}

template <typename T>
T* BatchEvaluator<T>::in(uint32_t var) {
  // Vars follow the uniforms in every tape derived from the same root.
  return regs_.data() + size_t(numUniformsBound_ + var) * kBatch;
}

template <typename T>
const T* BatchEvaluator<T>::eval(const Tape& tape, size_t count) {
  bind(tape);
  // Lanes past count hold stale but finite-or-not values; they are computed and ignored.
  size_t n = (count + 7) & ~size_t(7);
  if (n > kBatch) n = kBatch;
  const auto& code = tape.code();
  // sinCos[k]: instruction k's entry in the sin/cos pairing plan (nullptr: no pair)
  const uint32_t* sinCos = tape.sinCosPlan().empty() ? nullptr : tape.sinCosPlan().data();
  auto at = [&](size_t k) { return sinCos ? sinCos + k : nullptr; };
  const auto* fields = tape.fields().data();
  const uint32_t nu = tape.numUniforms();
  // The result's field call in sign-only mode runs apart (after the rest of the tape).
  const bool signTail = fieldSignsOnly_ && !code.empty() && code.back().op == Op::Field &&
                        code.back().out == tape.resultReg();
  const size_t size = code.size() - (signTail ? 1 : 0);
  if (!tape.hasExtrema()) {
    runTape<T>(code.data(), sinCos, size, regs_.data(), n, domain_, count, fields, nu);
  } else {
    // Straight-line segments between extremum instructions run vectorised as usual.
    size_t start = 0;
    for (size_t k = 0; k < code.size(); ++k) {
      if (code[k].op != Op::Extremum) continue;
      runTape<T>(code.data() + start, at(start), k - start, regs_.data(), n, domain_, count, fields, nu);
      runExtremum(tape, code[k], count);
      start = k + 1;
    }
    runTape<T>(code.data() + start, at(start), size - start, regs_.data(), n, domain_, count, fields, nu);
  }
  if (signTail) runField(*fields[size_t(code.back().imm)], code.back(), regs_.data(), n, true);
  return regs_.data() + size_t(tape.resultReg()) * kBatch;
}

template <typename T>
void BatchEvaluator<T>::runExtremum(const Tape& tape, const Instr& ins, size_t count) {
  const ExtremumEntry& e = tape.extrema()[ins.a];
  ExtremumSolver& solver = extrema_.get(tape, ins.a);
  const size_t nin = e.inputRegs.size();
  xbuf_.resize(nin);
  res_.resize(kBatch);
  bool haveWarm = false;
  const bool signOnly = signsOnly_ && !warmStarts_ && &ins == &tape.code().back() && ins.out == tape.resultReg();
  // Results go to a side buffer first: out may share a register with an input.
  for (size_t i = 0; i < count; ++i) {
    for (size_t k = 0; k < nin; ++k) xbuf_[k] = double(regs_[size_t(e.inputRegs[k]) * kBatch + i]);
    ExtremumResult r = signOnly ? solver.solveSign(xbuf_.data()) : solver.solve(xbuf_.data(), haveWarm ? warm_.data() : nullptr);
    res_[i] = r.value;
    if (warmStarts_ && !r.t.empty()) {
      warm_ = r.t;
      haveWarm = true;
    }
  }
  T* out = regs_.data() + size_t(ins.out) * kBatch;
  const size_t padded = std::min(kBatch, (count + 7) & ~size_t(7));
  for (size_t i = 0; i < count; ++i) out[i] = T(res_[i]);
  for (size_t i = count; i < padded; ++i) out[i] = T(0);
}

template class BatchEvaluator<float>;
template class BatchEvaluator<double>;

}  // namespace frep
