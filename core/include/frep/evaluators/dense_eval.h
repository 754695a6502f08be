// Evaluators of a DenseTape (frep/expressions/dense_tape.h): intervals over a box, recording the
// choices DenseSimplifier prunes by, and batches of points in float or double. Both agree with
// the Tape evaluators (eval.h) on every op, bit for bit: the interval pass takes the same
// decisions and bounds as IntervalEvaluator, a double batch gives BatchEvaluator<double>'s
// values, a float batch the rounding FloatErrorBound models. One evaluator per thread; each
// binds the constants of one root tape at a time (bind).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "frep/evaluators/interval.h"
#include "frep/expressions/dense_tape.h"

namespace frep {

class DenseIntervalEvaluator {
 public:
  // The constants of the root tape every later tape is derived from.
  void bind(const Tape& root);
  // Interval of the tape's result over the box (box[i]: var i). choices (tape.size() entries)
  // gets, at each min/max, 0 (both sides possible), 1 or 2 (the box decides for a or b, as
  // IntervalEvaluator decides); returns how many were decided in *decided.
  Interval eval(const DenseTape& tape, const Interval* box, uint8_t* choices, uint32_t* decided);
  // The same for four boxes in one pass (boxes[j * numVars + i]: var i of box j), each box's
  // results those eval gives it, bit for bit: choices[4 k + j] is box j's choice at
  // instruction k (4 * tape.size() entries), decided[j] and out[j] its count and interval.
  void eval4(const DenseTape& tape, const Interval* boxes, uint8_t* choices, uint32_t* decided, Interval* out);

  struct alignas(64) Iv4 {
    double lo[4], hi[4];
  };

 private:
  std::vector<Interval> regs_;
  std::vector<Iv4> regs4_;
  uint32_t numUniforms_ = 0;
};

template <typename T>
class DenseBatchEvaluator {
 public:
  static constexpr size_t kBatch = 256;
  void bind(const Tape& root);
  // Lanes of var i for the next eval (after bind; valid until the next bind or reserve).
  T* in(uint32_t var) { return regs_.data() + size_t(var) * kBatch; }
  // Makes room for the tape's registers; call before filling in() for a tape with more
  // registers than any before.
  void reserve(const DenseTape& tape);
  // The tape's value at lanes [0, count), count <= kBatch.
  const T* eval(const DenseTape& tape, size_t count);

 private:
  std::vector<T> consts_;  // register r < numUniforms_: one value
  std::vector<T> regs_;    // register r >= numUniforms_: kBatch lanes from (r - numUniforms_) * kBatch
  std::vector<T> result_;  // a constant result's lanes
  uint32_t numUniforms_ = 0;
};
extern template class DenseBatchEvaluator<float>;
extern template class DenseBatchEvaluator<double>;

}  // namespace frep
