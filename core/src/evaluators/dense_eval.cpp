// DenseTape evaluators (dense_eval.h). The interval pass runs interval_fast.h's inlined ops (the
// bits of applyOp) and IntervalEvaluator's min/max rule; the batch kernel is one switch over the
// subset's ops in lane loops the compiler vectorises, compiled per ISA level (isa_clones.h),
// with the scalar rules of BatchEvaluator (sqrt(max(a, 0)), min = b < a ? b : a, ...).
#include "frep/evaluators/dense_eval.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "evaluators/interval_fast.h"
#include "isa_clones.h"

namespace frep {

void DenseIntervalEvaluator::bind(const Tape& root) {
  const auto& u = root.uniforms();
  numUniforms_ = uint32_t(u.size());
  if (regs_.size() < root.numRegs()) regs_.resize(root.numRegs());
  // A constant folded to NaN becomes everything(), IntervalEvaluator's NaN marker.
  for (size_t i = 0; i < u.size(); ++i) regs_[i] = std::isnan(u[i]) ? Interval::everything() : Interval(u[i]);
  if (regs4_.size() < root.numRegs()) regs4_.resize(root.numRegs());
  for (size_t i = 0; i < u.size(); ++i)
    for (int j = 0; j < 4; ++j) regs4_[i].lo[j] = regs_[i].lo, regs4_[i].hi[j] = regs_[i].hi;
}

namespace {

// One instruction over one box, as IntervalEvaluator: min is b < a ? b : a, max b > a ? b : a,
// and a side is kept (*ch = 1 or 2) only when it is the scalar rule's pick at every point (ties
// keep a; a possibly-NaN operand is everything(), never decided); x * x is x^2 bit for bit,
// and x^2 is the tighter bound.
inline __attribute__((always_inline)) Interval step(const DenseInstr& ins, const Interval& a, const Interval& b,
                                                    uint8_t* ch) {
  if (ins.op == Op::Min || ins.op == Op::Max) {
    const uint8_t c = ins.op == Op::Min ? (a.hi <= b.lo  ? 1
                                           : b.hi < a.lo ? 2
                                                         : 0)
                                        : (b.hi <= a.lo  ? 1
                                           : b.lo > a.hi ? 2
                                                         : 0);
    *ch = c;
    if (c) return c == 1 ? a : b;
  }
  const Op op = ins.op == Op::PowI || (ins.op == Op::Mul && ins.a == ins.b) ? Op::PowI : ins.op;
  Interval v;
  if (!detail::fastOp(op, a, b, 2.0, v)) v = applyOp(op, a, b, Interval(), 2.0);
  return v;
}

}  // namespace

Interval DenseIntervalEvaluator::eval(const DenseTape& tape, const Interval* box, uint8_t* choices, uint32_t* decided) {
  if (regs_.size() < tape.numRegs) regs_.resize(tape.numRegs);
  Interval* r = regs_.data();
  for (uint32_t i = 0; i < tape.numVars; ++i) r[numUniforms_ + i] = box[i];
  uint32_t n = 0;
  const DenseInstr* code = tape.code.data();
  for (size_t k = 0, size = tape.code.size(); k < size; ++k) {
    const DenseInstr& ins = code[k];
    uint8_t ch = 0;
    r[ins.out] = step(ins, r[ins.a], r[ins.b], &ch);
    choices[k] = ch;
    n += ch != 0;
  }
  *decided = n;
  return r[tape.result];
}

namespace {

// Four lanes of doubles (GCC vector extensions: one AVX2 register, two SSE2 ones), and their
// comparison masks (-1: true). The ternaries below are std::min / std::max / fastOp's
// selections written lane-wise, so each lane gets fastOp's bits.
// (All inlined into the kernel: the note GCC gives on returning such vectors without AVX is moot.)
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double V4 __attribute__((vector_size(32)));
typedef int64_t M4 __attribute__((vector_size(32)));
typedef uint64_t U4 __attribute__((vector_size(32)));  // bit steps wrap (NaN lanes, discarded)

inline V4 load4(const double* p) {
  V4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(double* p, V4 v) { std::memcpy(p, &v, sizeof v); }
inline V4 sel(M4 m, V4 a, V4 b) { return m ? a : b; }
inline V4 vmin(V4 a, V4 b) { return sel(b < a, b, a); }  // std::min(a, b)
inline V4 vmax(V4 a, V4 b) { return sel(a < b, b, a); }  // std::max(a, b)

// nextUp of interval_fast.h lane-wise (the same bits): the step's sign from a compare, which
// vectorises where a 64-bit arithmetic shift does not (AVX2).
inline V4 up4(V4 x) {
  const V4 zero = {0, 0, 0, 0}, inf = {INFINITY, INFINITY, INFINITY, INFINITY};
  const V4 y = x + zero;  // -0 -> +0
  U4 bits;
  std::memcpy(&bits, &y, sizeof bits);
  bits += U4((y < zero) | 1);
  V4 r;
  std::memcpy(&r, &bits, sizeof r);
  return sel(x < inf, r, x);
}
inline V4 down4(V4 x) { return -up4(-x); }
inline bool all(M4 m) { return (m[0] & m[1] & m[2] & m[3]) != 0; }
inline V4 fabs4(V4 x) {
  M4 b;
  std::memcpy(&b, &x, sizeof b);
  b &= INT64_MAX;
  V4 r;
  std::memcpy(&r, &b, sizeof r);
  return r;
}

// Four boxes per pass: the dispatch is paid once per instruction and the bounds are computed
// in vector lanes. An instruction whose operands are not all finite, where fastOp would hand
// over to applyOp, and square roots run lane by lane (step).
FREP_CLONES void runInterval4(const DenseInstr* code, size_t size, DenseIntervalEvaluator::Iv4* R, uint8_t* choices,
                              uint32_t* decided) {
  const V4 zero = {0, 0, 0, 0}, inf = {INFINITY, INFINITY, INFINITY, INFINITY};
  M4 d = {0, 0, 0, 0};
  for (size_t k = 0; k < size; ++k) {
    const DenseInstr& ins = code[k];
    const V4 alo = load4(R[ins.a].lo), ahi = load4(R[ins.a].hi);
    const V4 blo = load4(R[ins.b].lo), bhi = load4(R[ins.b].hi);
    uint8_t* ch = choices + 4 * k;
    std::memset(ch, 0, 4);
    const bool square = ins.op == Op::PowI || (ins.op == Op::Mul && ins.a == ins.b);
    const bool bin = !square && (ins.op == Op::Add || ins.op == Op::Sub || ins.op == Op::Mul || ins.op == Op::Min ||
                                 ins.op == Op::Max);
    bool fin;
    if (bin) {
      const V4 s = (alo + ahi) + (blo + bhi);
      fin = all(s - s == zero);
    } else {
      fin = all((fabs4(alo) < inf) & (fabs4(ahi) < inf));
    }
    if (!fin || ins.op == Op::Sqrt) {
      DenseIntervalEvaluator::Iv4 v;
      for (int j = 0; j < 4; ++j) {
        uint8_t c = 0;
        const Interval r = step(ins, Interval(alo[j], ahi[j]), Interval(blo[j], bhi[j]), &c);
        v.lo[j] = r.lo, v.hi[j] = r.hi, ch[j] = c, d[j] += c != 0;
      }
      R[ins.out] = v;
      continue;
    }
    V4 lo, hi;
    if (square) {
      const V4 l = fabs4(alo), h = fabs4(ahi);
      const V4 minAbs = sel((alo <= zero) & (ahi >= zero), zero, vmin(l, h));
      const V4 maxAbs = vmax(l, h);
      const V4 m = down4(minAbs * minAbs);
      lo = sel(m < zero, zero, m);
      hi = up4(maxAbs * maxAbs);
    } else {
      switch (ins.op) {
        case Op::Add:
          lo = down4(alo + blo), hi = up4(ahi + bhi);
          break;
        case Op::Sub:
          lo = down4(alo - bhi), hi = up4(ahi - blo);
          break;
        case Op::Mul: {
          const V4 p0 = alo * blo, p1 = alo * bhi, p2 = ahi * blo, p3 = ahi * bhi;
          lo = down4(vmin(vmin(p0, p1), vmin(p2, p3)));
          hi = up4(vmax(vmax(p0, p1), vmax(p2, p3)));
          break;
        }
        case Op::Min:
        case Op::Max: {
          // A decided side's bounds are what min (max) of the bounds gives on finite
          // operands, so only the choices differ from the undecided case.
          const bool isMin = ins.op == Op::Min;
          const M4 keepA = isMin ? ahi <= blo : bhi <= alo, keepB = isMin ? bhi < alo : blo > ahi;
          const M4 c = (keepA & 1) | (keepB & 2);
          for (int j = 0; j < 4; ++j) ch[j] = uint8_t(c[j]);
          d += (c != 0) & 1;
          lo = isMin ? vmin(alo, blo) : vmax(alo, blo);
          hi = isMin ? vmin(ahi, bhi) : vmax(ahi, bhi);
          break;
        }
        case Op::Neg:
          lo = -ahi, hi = -alo;
          break;
        case Op::Abs: {
          const M4 pos = alo >= zero, neg = ahi <= zero;
          lo = sel(pos, alo, sel(neg, -ahi, zero));
          hi = sel(pos, ahi, sel(neg, -alo, vmax(-alo, ahi)));
          break;
        }
        default:
          lo = alo, hi = ahi;
          break;  // Copy
      }
    }
    store4(R[ins.out].lo, lo);
    store4(R[ins.out].hi, hi);
  }
  for (int j = 0; j < 4; ++j) decided[j] = uint32_t(d[j]);
}

}  // namespace

void DenseIntervalEvaluator::eval4(const DenseTape& tape, const Interval* boxes, uint8_t* choices, uint32_t* decided,
                                   Interval* out) {
  if (regs4_.size() < tape.numRegs) regs4_.resize(tape.numRegs);
  Iv4* R = regs4_.data();
  for (uint32_t i = 0; i < tape.numVars; ++i)
    for (int j = 0; j < 4; ++j) {
      R[numUniforms_ + i].lo[j] = boxes[size_t(j) * tape.numVars + i].lo;
      R[numUniforms_ + i].hi[j] = boxes[size_t(j) * tape.numVars + i].hi;
    }
  runInterval4(tape.code.data(), tape.code.size(), R, choices, decided);
  for (int j = 0; j < 4; ++j) out[j] = Interval(R[tape.result].lo[j], R[tape.result].hi[j]);
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
// Register r >= nu is regs[(r - nu) * B ...], a constant r < nu is consts[r].
template <typename T>
FREP_CLONES void runDense(const DenseInstr* code, size_t size, const T* consts, T* regs, size_t n, uint32_t nu) {
  constexpr size_t B = DenseBatchEvaluator<T>::kBatch;
  for (size_t k = 0; k < size; ++k) {
    const DenseInstr& ins = code[k];
    const bool ac = ins.a < nu, bc = ins.b < nu;
    const T* a = ac ? consts + ins.a : regs + size_t(ins.a - nu) * B;
    const T* b = bc ? consts + ins.b : regs + size_t(ins.b - nu) * B;
    T* o = regs + size_t(ins.out - nu) * B;
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
  consts_.resize(u.size());
  for (size_t i = 0; i < u.size(); ++i) consts_[i] = T(u[i]);
  // The vars; temporaries as tapes need them (reserve): pruned ones need few.
  if (regs_.size() < size_t(root.numVars()) * kBatch) regs_.resize(size_t(root.numVars()) * kBatch);
}

template <typename T>
void DenseBatchEvaluator<T>::reserve(const DenseTape& tape) {
  const size_t need = size_t(tape.numRegs - numUniforms_) * kBatch;
  if (regs_.size() < need) regs_.resize(need);
}

template <typename T>
const T* DenseBatchEvaluator<T>::eval(const DenseTape& tape, size_t count) {
  reserve(tape);
  // Whole vectors: the lanes past count are computed and ignored.
  const size_t n = std::min(kBatch, (count + 7) & ~size_t(7));
  runDense<T>(tape.code.data(), tape.code.size(), consts_.data(), regs_.data(), n, numUniforms_);
  if (tape.result >= numUniforms_) return regs_.data() + size_t(tape.result - numUniforms_) * kBatch;
  // A constant model (a tape with no instruction)
  result_.assign(kBatch, consts_[tape.result]);
  return result_.data();
}

template class DenseBatchEvaluator<float>;
template class DenseBatchEvaluator<double>;

}  // namespace frep
