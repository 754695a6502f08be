// The four evaluators that walk a compiled Tape. Each owns its register file, so use one
// evaluator per thread. All agree with applyOp (expr.h) on every op.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"

namespace frep {

class ExtremumSolver;  // extremum.h

// The search engines an evaluator needs for a tape's Op::Extremum instructions, one per entry
// of the tape's extremum table, created on first use and rebuilt when the evaluator moves to
// another root tape. Copies start empty (a solver holds its own evaluators).
class ExtremumSlots {
 public:
  ExtremumSlots();
  ~ExtremumSlots();
  ExtremumSlots(const ExtremumSlots&);
  ExtremumSlots& operator=(const ExtremumSlots&);
  ExtremumSolver& get(const Tape& tape, uint32_t entry);

 private:
  uint64_t rootId_ = 0;
  std::vector<std::unique_ptr<ExtremumSolver>> solvers_;
};

// 1. Point evaluation in double precision: the reference.
class PointEvaluator {
 public:
  double eval(const Tape& tape, const double* x);
  // Adds every domain error of later evals to *counts (nullptr: stop counting).
  void countDomainErrors(DomainCounts* counts) { domain_ = counts; }
  // Extremum searches. After an eval, searchParams()[e] holds the arg-extremum (search
  // parameters) found for the tape's extremum entry e, empty when that entry was not reached.
  // setWarmStarts(w): later evals also start entry e's search from (*w)[e] when it has the
  // search's size, so their values depend on w; nullptr (the default): every value is a
  // function of its point alone.
  const std::vector<std::vector<double>>& searchParams() const { return params_; }
  void setWarmStarts(const std::vector<std::vector<double>>* warm) { warm_ = warm; }

 private:
  DomainCounts* domain_ = nullptr;
  std::vector<double> regs_;
  uint64_t boundId_ = 0;
  ExtremumSlots extrema_;
  std::vector<double> xbuf_;
  std::vector<std::vector<double>> params_;
  const std::vector<std::vector<double>>* warm_ = nullptr;
};

// 2. Batch evaluation over up to kBatch points in structure-of-arrays form.
//    Usage: fill in(i)[k] for var i and point k < count, call eval, read out()[k].
//    Extremum instructions run one search per lane, each lane warm-started from the previous
//    lane's arg-extremum within the same eval call (neighbouring voxels); nothing carries over
//    between calls, so results do not depend on the order of calls (determinism).
template <typename T>
class BatchEvaluator {
 public:
  static constexpr size_t kBatch = 256;
  T* in(uint32_t var);  // valid after reserve(tape) or a previous eval with that tape
  void reserve(const Tape& tape);
  const T* eval(const Tape& tape, size_t count);
  // Adds the domain errors of later evals (lanes < count) to *counts (nullptr: stop).
  void countDomainErrors(DomainCounts* counts) { domain_ = counts; }
  // false: every lane's search starts cold, so each value is a function of its point alone
  // (the PointEvaluator's value), at about twice the cost of warm-started lanes.
  void setExtremumWarmStarts(bool on) { warmStarts_ = on; }
  // true (with warm starts off): an extremum that is the tape's last instruction and result
  // runs ExtremumSolver::solveSign, so only the sign of each value is that of the cold search
  // (what the mesher reads from its sample), at a fraction of the cost away from the surface.
  void setExtremumSignsOnly(bool on) { signsOnly_ = on; }
  // true: a field call that is the tape's last instruction and result gives only the class of
  // each value (FieldFunction::signs): for callers that read insideValue() alone.
  void setFieldSignsOnly(bool on) { fieldSignsOnly_ = on; }

 private:
  DomainCounts* domain_ = nullptr;
  bool warmStarts_ = true;
  bool signsOnly_ = false;
  bool fieldSignsOnly_ = false;
  void bind(const Tape& tape);
  void runExtremum(const Tape& tape, const Instr& ins, size_t count);
  std::vector<T> regs_;  // numRegs * kBatch, register-major
  uint64_t boundId_ = 0;
  uint32_t numUniformsBound_ = 0;
  ExtremumSlots extrema_;
  std::vector<double> xbuf_, warm_, res_;
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
  // Extremum nodes: by default their bound stops refining as soon as its sign is decided (all
  // that inside/outside classification needs). An outer search needs tight upper bounds
  // instead: signOnly = false (the extremum solver sets it for its body).
  void setExtremumSignOnly(bool signOnly) { extremumSignOnly_ = signOnly; }
  // true: the sign-only bound stops at its budget (ExtremumSolver::bound's budgetOnly).
  void setExtremumBudgetOnly(bool on) { extremumBudgetOnly_ = on; }

 private:
  std::vector<Interval> regs_;
  std::vector<Choice> choices_;
  uint64_t boundId_ = 0;
  ExtremumSlots extrema_;
  std::vector<Interval> xbuf_;
  bool extremumSignOnly_ = true;
  bool extremumBudgetOnly_ = false;
};

// 4. Forward-mode gradient: value and d/dx[i] for every coordinate of the tape. An extremum
//    node's derivative follows Danskin's theorem: d/dX max_u g = dg/dX at the maximiser.
class GradientEvaluator {
 public:
  // grad must hold tape.numVars() doubles.
  double eval(const Tape& tape, const double* x, double* grad);

 private:
  std::vector<double> val_, der_;  // der_: numRegs * numVars
  uint64_t boundId_ = 0;
  ExtremumSlots extrema_;
  std::vector<double> xbuf_, gbuf_, row_;
};

// 5. Forward-mode gradients of up to kBatch points at once, in structure-of-arrays form: for
//    every lane the same value and partials, bit for bit, as GradientEvaluator::eval, whose
//    formulas it runs lane by lane (the common ops as vectorised loops). Only the partials along
//    x[1..3] are kept (the others are independent of them). Tapes with extremum or field nodes
//    go through GradientEvaluator lane by lane, in lane order.
//    Usage: fill in(i)[k] for var i and point k < count (every var, x[4..] included), call eval,
//    read value()[k] and partial(axis)[k] (axis 0..2; 0 past the tape's vars).
class BatchGradientEvaluator {
 public:
  static constexpr size_t kBatch = 256;
  void reserve(const Tape& tape);
  double* in(uint32_t var);  // valid after reserve(tape)
  void eval(const Tape& tape, size_t count);
  const double* value() const { return out_.data(); }
  const double* partial(int axis) const { return out_.data() + size_t(axis + 1) * kBatch; }

 private:
  void bind(const Tape& tape);
  std::vector<double> val_, der_;  // val_: numRegs * kBatch; der_: (numRegs * 3 + axis) * kBatch
  std::vector<double> out_ = std::vector<double>(4 * kBatch, 0.0);  // value, then 3 partials
  std::vector<double> x_, g_;
  std::vector<double> scratch_ = std::vector<double>(3 * kBatch);  // runGradientTape's p, q, t
  std::vector<char> pick_ = std::vector<char>(kBatch);
  uint64_t boundId_ = 0;
  uint32_t numUniformsBound_ = 0;
  GradientEvaluator scalar_;  // tapes with extremum or field nodes
};

}  // namespace frep
