// The four evaluators that walk a compiled Tape. Each owns its register file, so use one
// evaluator per thread. All agree with applyOp (expr.h) on every op.
#pragma once

#include <cstddef>
#include <vector>

#include "frep/interval.h"
#include "frep/tape.h"

namespace frep {

// 1. Point evaluation in double precision: the reference.
class PointEvaluator {
 public:
  double eval(const Tape& tape, const double* x);

 private:
  std::vector<double> regs_;
  uint64_t boundId_ = 0;
};

// 2. Batch evaluation over up to kBatch points in structure-of-arrays form.
//    Usage: fill in(i)[k] for var i and point k < count, call eval, read out()[k].
template <typename T>
class BatchEvaluator {
 public:
  static constexpr size_t kBatch = 256;
  T* in(uint32_t var);  // valid after reserve(tape) or a previous eval with that tape
  void reserve(const Tape& tape);
  const T* eval(const Tape& tape, size_t count);

 private:
  void bind(const Tape& tape);
  std::vector<T> regs_;  // numRegs * kBatch, register-major
  uint64_t boundId_ = 0;
  uint32_t numUniformsBound_ = 0;
};
extern template class BatchEvaluator<float>;
extern template class BatchEvaluator<double>;

// 3. Interval evaluation over boxes, recording which side each min/max/select takes.
class IntervalEvaluator {
 public:
  Interval eval(const Tape& tape, const Interval* box);
  // Choices made by the last eval (one per instruction of that tape).
  const std::vector<Choice>& choices() const { return choices_; }
  // Shortened tape valid inside the last evaluated box (self: the tape last evaluated).
  TapePtr pruned(const TapePtr& self) const { return self->prune(choices_, self); }

 private:
  std::vector<Interval> regs_;
  std::vector<Choice> choices_;
  uint64_t boundId_ = 0;
};

// 4. Forward-mode gradient: value and d/dx[i] for every coordinate of the tape.
class GradientEvaluator {
 public:
  // grad must hold tape.numVars() doubles.
  double eval(const Tape& tape, const double* x, double* grad);

 private:
  std::vector<double> val_, der_;  // der_: numRegs * numVars
  uint64_t boundId_ = 0;
};

}  // namespace frep
