// DenseTape evaluators (dense_eval.h). The interval pass runs interval_fast.h's inlined ops (the
// bits of applyOp) and IntervalEvaluator's min/max rule; the batch kernel is one switch over the
// subset's ops in lane loops the compiler vectorises, compiled per ISA level (isa_clones.h),
// with the scalar rules of BatchEvaluator (sqrt(max(a, 0)), min = b < a ? b : a, ...).
#include "frep/evaluators/dense_eval.h"

#include <algorithm>
#include <cmath>

#include "evaluators/interval_fast.h"
#include "isa_clones.h"

namespace frep {

void DenseIntervalEvaluator::bind(const Tape& root) {
  const auto& u = root.uniforms();
  numUniforms_ = uint32_t(u.size());
  if (regs_.size() < root.numRegs()) regs_.resize(root.numRegs());
  // A constant folded to NaN becomes everything(), IntervalEvaluator's NaN marker.
  for (size_t i = 0; i < u.size(); ++i) regs_[i] = std::isnan(u[i]) ? Interval::everything() : Interval(u[i]);
}

Interval DenseIntervalEvaluator::eval(const DenseTape& tape, const Interval* box, uint8_t* choices, uint32_t* decided) {
  if (regs_.size() < tape.numRegs) regs_.resize(tape.numRegs);
  Interval* r = regs_.data();
  for (uint32_t i = 0; i < tape.numVars; ++i) r[numUniforms_ + i] = box[i];
  uint32_t n = 0;
  const DenseInstr* code = tape.code.data();
  for (size_t k = 0, size = tape.code.size(); k < size; ++k) {
    const DenseInstr& ins = code[k];
    const Interval a = r[ins.a], b = r[ins.b];
    Interval v;
    // min: b < a ? b : a, max: b > a ? b : a; a side is kept only when it is the scalar rule's
    // pick at every point (ties keep a; a possibly-NaN operand is everything(), never decided)
    if (ins.op == Op::Min || ins.op == Op::Max) {
      const bool isMin = ins.op == Op::Min;
      const uint8_t ch = isMin ? (a.hi <= b.lo ? 1 : b.hi < a.lo ? 2 : 0) : (b.hi <= a.lo ? 1 : b.lo > a.hi ? 2 : 0);
      choices[k] = ch;
      if (ch) {
        r[ins.out] = ch == 1 ? a : b;
        ++n;
        continue;
      }
    }
    // x * x is x^2 bit for bit, and x^2 is the tighter bound (as IntervalEvaluator)
    const bool square = ins.op == Op::PowI || (ins.op == Op::Mul && ins.a == ins.b);
    const Op op = square ? Op::PowI : ins.op;
    if (!detail::fastOp(op, a, b, 2.0, v)) v = applyOp(op, a, b, Interval(), 2.0);
    r[ins.out] = v;
  }
  *decided = n;
  return r[tape.result];
}

namespace {

// o = f(a, b) over n lanes; a constant operand (its register below nu) is read once from lane 0.
template <typename T, typename F>
inline __attribute__((always_inline)) void binaryLoop(const T* a, bool ac, const T* b, bool bc, T* o, size_t n, F f) {
  if (ac && bc) {
    const T v = f(a[0], b[0]);
    for (size_t i = 0; i < n; ++i) o[i] = v;
  } else if (bc) {
    const T y = b[0];
    for (size_t i = 0; i < n; ++i) o[i] = f(a[i], y);
  } else if (ac) {
    const T x = a[0];
    for (size_t i = 0; i < n; ++i) o[i] = f(x, b[i]);
  } else {
    for (size_t i = 0; i < n; ++i) o[i] = f(a[i], b[i]);
  }
}

template <typename T, typename F>
inline __attribute__((always_inline)) void unaryLoop(const T* a, bool ac, T* o, size_t n, F f) {
  if (ac) {
    const T v = f(a[0]);
    for (size_t i = 0; i < n; ++i) o[i] = v;
  } else {
    for (size_t i = 0; i < n; ++i) o[i] = f(a[i]);
  }
}

// No __restrict on o: an output may be one of its inputs' registers (lane i reads, then writes i).
template <typename T>
FREP_CLONES void runDense(const DenseInstr* code, size_t size, T* regs, size_t n, uint32_t nu) {
  constexpr size_t B = DenseBatchEvaluator<T>::kBatch;
  for (size_t k = 0; k < size; ++k) {
    const DenseInstr& ins = code[k];
    const T* a = regs + size_t(ins.a) * B;
    const T* b = regs + size_t(ins.b) * B;
    T* o = regs + size_t(ins.out) * B;
    const bool ac = ins.a < nu, bc = ins.b < nu;
    switch (ins.op) {
      case Op::Add:
        binaryLoop(a, ac, b, bc, o, n, [](T x, T y) { return x + y; });
        break;
      case Op::Sub:
        binaryLoop(a, ac, b, bc, o, n, [](T x, T y) { return x - y; });
        break;
      case Op::Mul:
        binaryLoop(a, ac, b, bc, o, n, [](T x, T y) { return x * y; });
        break;
      case Op::Min:
        binaryLoop(a, ac, b, bc, o, n, [](T x, T y) { return y < x ? y : x; });
        break;
      case Op::Max:
        binaryLoop(a, ac, b, bc, o, n, [](T x, T y) { return y > x ? y : x; });
        break;
      case Op::Neg:
        unaryLoop(a, ac, o, n, [](T x) { return -x; });
        break;
      case Op::Abs:
        unaryLoop(a, ac, o, n, [](T x) { return std::fabs(x); });
        break;
      case Op::Sqrt:
        unaryLoop(a, ac, o, n, [](T x) { return std::sqrt(x > T(0) ? x : T(0)); });
        break;
      case Op::PowI:
        unaryLoop(a, ac, o, n, [](T x) { return x * x; });
        break;
      default:
        unaryLoop(a, ac, o, n, [](T x) { return x; });
        break;  // Copy
    }
  }
}

}  // namespace

template <typename T>
void DenseBatchEvaluator<T>::bind(const Tape& root) {
  const auto& u = root.uniforms();
  numUniforms_ = uint32_t(u.size());
  // The constants and vars; temporaries as tapes need them (reserve): pruned ones need few.
  const size_t fixed = size_t(numUniforms_ + root.numVars()) * kBatch;
  if (regs_.size() < fixed) regs_.resize(fixed);
  for (size_t i = 0; i < u.size(); ++i) regs_[i * kBatch] = T(u[i]);
}

template <typename T>
void DenseBatchEvaluator<T>::reserve(const DenseTape& tape) {
  if (regs_.size() < size_t(tape.numRegs) * kBatch) regs_.resize(size_t(tape.numRegs) * kBatch);
}

template <typename T>
const T* DenseBatchEvaluator<T>::eval(const DenseTape& tape, size_t count) {
  reserve(tape);
  // Whole vectors: the lanes past count are computed and ignored.
  const size_t n = std::min(kBatch, (count + 7) & ~size_t(7));
  runDense<T>(tape.code.data(), tape.code.size(), regs_.data(), n, numUniforms_);
  return regs_.data() + size_t(tape.result) * kBatch;
}

template class DenseBatchEvaluator<float>;
template class DenseBatchEvaluator<double>;

}  // namespace frep
