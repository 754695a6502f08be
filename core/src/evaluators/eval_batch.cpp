// Batch evaluator: one pass over the tape per batch of points, each instruction a tight loop
// over structure-of-arrays lanes that the compiler vectorises (arithmetic, min/max, sqrt,
// comparisons, select); transcendentals call libm per lane. The kernel is compiled for several
// ISA levels (target_clones) and picked at run time; -ffp-contract=off keeps every clone
// bit-identical to the others and to the point evaluator for + - * / sqrt.
#include <algorithm>
#include <cmath>
#include <math.h>  // sincos, sincosf (GNU)

#include "frep/evaluators/eval.h"
#include "frep/expressions/pow_int.h"
#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"

namespace frep {

namespace {


#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FREP_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define FREP_CLONES
#endif

// sin and cos in one call. glibc's sincos/sincosf share the code paths of sin/cos and
// sinf/cosf, so the bits are the same (checked on doubles over the whole range and on every
// float); elsewhere, two calls.
inline void sinCos(double x, double& s, double& c) {
#ifdef __GLIBC__
  ::sincos(x, &s, &c);
#else
  s = std::sin(x), c = std::cos(x);
#endif
}
inline void sinCos(float x, float& s, float& c) {
#ifdef __GLIBC__
  ::sincosf(x, &s, &c);
#else
  s = std::sin(x), c = std::cos(x);
#endif
}

// A Sin or Cos the tape's sinCosPlan pairs: the first of the pair writes both outputs (the
// partner's register is free until the partner, see planSinCos), the second has nothing left
// to do.
template <typename T>
void runSinCos(const Instr& ins, uint32_t partnerOut, T* regs, size_t n) {
  if (partnerOut == Tape::kSinCosDone) return;
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  const T* a = regs + size_t(ins.a) * B;
  T* s = regs + size_t(ins.out) * B;
  T* c = regs + size_t(partnerOut) * B;
  if (ins.op == Op::Cos) std::swap(s, c);
  for (size_t i = 0; i < n; ++i) {
    T sv, cv;
    sinCos(a[i], sv, cv);  // a may be the partner's output register: read before writing
    s[i] = sv;
    c[i] = cv;
  }
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
void runField(const FieldFunction& fn, const Instr& ins, T* regs, size_t n) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  thread_local std::vector<double> buf;
  buf.resize(4 * B);
  double *u = buf.data(), *v = u + B, *w = v + B, *out = w + B;
  const T* a = regs + size_t(ins.a) * B;
  const T* b = regs + size_t(ins.b) * B;
  const T* c = regs + size_t(ins.c) * B;
  for (size_t i = 0; i < n; ++i) u[i] = double(a[i]), v[i] = double(b[i]), w[i] = double(c[i]);
  fn.values(u, v, w, out, n);
  T* o = regs + size_t(ins.out) * B;
  for (size_t i = 0; i < n; ++i) o[i] = T(out[i]);
}

template <typename T>
FREP_CLONES void runTape(const Instr* code, const uint32_t* sinCos, size_t ninstr, T* __restrict regs, size_t n,
                         DomainCounts* dom, size_t count, const std::shared_ptr<const FieldFunction>* fields) {
  constexpr size_t B = BatchEvaluator<T>::kBatch;
  for (size_t k = 0; k < ninstr; ++k) {
    const Instr& ins = code[k];
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
      case Op::Sqrt: LOOP(a[i] > T(0) ? std::sqrt(a[i]) : T(0));
      case Op::Exp: LOOP(std::exp(a[i]));
      case Op::Log: LOOP(T(std::log(double(a[i]) > kLogFloor ? double(a[i]) : kLogFloor)));
      case Op::Log10: LOOP(T(std::log10(double(a[i]) > kLogFloor ? double(a[i]) : kLogFloor)));
      case Op::Sin:
        if (sinCos && sinCos[k] != Tape::kNoSinCos) {
          runSinCos(ins, sinCos[k], regs, n);
          break;
        }
        LOOP(std::sin(a[i]));
      case Op::Cos:
        if (sinCos && sinCos[k] != Tape::kNoSinCos) {
          runSinCos(ins, sinCos[k], regs, n);
          break;
        }
        LOOP(std::cos(a[i]));
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
      case Op::Add: LOOP(a[i] + b[i]);
      case Op::Sub: LOOP(a[i] - b[i]);
      case Op::Mul: LOOP(a[i] * b[i]);
      case Op::Div: LOOP(a[i] / b[i]);
      case Op::Pow: LOOP(std::pow(a[i], b[i]));
      case Op::Atan2: LOOP(std::atan2(a[i], b[i]));
      case Op::Min: LOOP(b[i] < a[i] ? b[i] : a[i]);
      case Op::Max: LOOP(b[i] > a[i] ? b[i] : a[i]);
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
            T root = s > T(0) ? std::sqrt(s) : T(0);
            o[i] = a[i] + b[i] + sg * root;
          }
        } else {
          for (size_t i = 0; i < n; ++i) {
            T s = a[i] * a[i] + b[i] * b[i] - T(2) * al * a[i] * b[i];
            T root = s > T(0) ? std::sqrt(s) : T(0);
            o[i] = (a[i] + b[i] + sg * root) / (T(1) + al);
          }
        }
        break;
      }
      default: break;
    }
#undef LOOP
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
  if (!tape.hasExtrema()) {
    runTape<T>(code.data(), sinCos, code.size(), regs_.data(), n, domain_, count, fields);
  } else {
    // Straight-line segments between extremum instructions run vectorised as usual.
    size_t start = 0;
    for (size_t k = 0; k < code.size(); ++k) {
      if (code[k].op != Op::Extremum) continue;
      runTape<T>(code.data() + start, at(start), k - start, regs_.data(), n, domain_, count, fields);
      runExtremum(tape, code[k], count);
      start = k + 1;
    }
    runTape<T>(code.data() + start, at(start), code.size() - start, regs_.data(), n, domain_, count, fields);
  }
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
  // Results go to a side buffer first: out may share a register with an input.
  for (size_t i = 0; i < count; ++i) {
    for (size_t k = 0; k < nin; ++k) xbuf_[k] = double(regs_[size_t(e.inputRegs[k]) * kBatch + i]);
    ExtremumResult r = solver.solve(xbuf_.data(), haveWarm ? warm_.data() : nullptr);
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
