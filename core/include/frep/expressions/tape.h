// Compiled tape: the DAG flattened into straight-line code over a register file.
//
// Register layout: [0, numUniforms) hold constants (filled once when an evaluator binds the
// tape), [numUniforms, numUniforms + numVars) hold the coordinates, the rest are temporaries
// reused as soon as their last reader has run (linear-scan allocation). A pruned tape (see
// prune) keeps the same layout and uniforms, so evaluators can switch tapes cheaply.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep {

struct Instr {
  Op op;
  uint32_t out;
  uint32_t a = 0, b = 0, c = 0;  // input registers (by arity)
  double imm = 0.0;              // PowI exponent
};

// Per-instruction decision taken by interval evaluation over a box.
enum class Choice : uint8_t { Both = 0, KeepA = 1, KeepB = 2 };

class Tape;
using TapePtr = std::shared_ptr<const Tape>;

// An Op::Extremum instruction's `a` indexes the tape's table of these (shared by pruned tapes):
// the spec, the registers holding its n inputs, and its body compiled to its own tape.
struct ExtremumEntry {
  std::shared_ptr<const ExtremumSpec> spec;
  std::vector<uint32_t> inputRegs;
  TapePtr body;
};

class Tape {
 public:
  // Compiles e. Parameters must have been bound (bindParams) before; a Param left in e is an
  // error (std::invalid_argument). numVars may exceed the vars e uses (extra vars are ignored).
  static TapePtr compile(const Expr& e, uint32_t numVars = 0);

  uint32_t numVars() const { return numVars_; }
  uint32_t numRegs() const { return numRegs_; }
  uint32_t numUniforms() const { return static_cast<uint32_t>(uniforms_->size()); }
  uint32_t varReg(uint32_t i) const { return numUniforms() + i; }
  uint32_t resultReg() const { return result_; }
  const std::vector<double>& uniforms() const { return *uniforms_; }
  const std::vector<Instr>& code() const { return code_; }
  size_t size() const { return code_.size(); }
  // Number of min/max/select instructions a box could decide (0: pruning cannot help).
  uint32_t numChoices() const { return numChoices_; }
  const Tape* root() const { return root_ ? root_.get() : this; }
  uint64_t id() const { return id_; }  // unique per tape object (evaluator caches)
  // Extremum instructions (an extremum is not a choice: interval pruning leaves it in place).
  const std::vector<ExtremumEntry>& extrema() const { return *extrema_; }
  bool hasExtrema() const { return !extrema_->empty(); }
  // Objects of Op::Field instructions (an instruction's imm is its index; shared by pruned tapes).
  const std::vector<std::shared_ptr<const FieldFunction>>& fields() const { return *fields_; }
  const FieldFunction& field(const Instr& ins) const { return *(*fields_)[size_t(ins.imm)]; }

  // Sin/Cos pairs of the same input value that the batch evaluator computes in one pass at the
  // first of the two (ownSinCos, sin_cos.h, gives both from one reduction): rotations and
  // gyroids take both of one angle. Per instruction: for the first of a
  // pair, the output register of the second (written at once); kSinCosDone for the second;
  // kNoSinCos for the rest. Empty when the tape has no pair. Built by compile and prune.
  static constexpr uint32_t kNoSinCos = UINT32_MAX, kSinCosDone = UINT32_MAX - 1;
  const std::vector<uint32_t>& sinCosPlan() const { return sinCos_; }

  // A shorter tape, valid wherever the choices hold: decided min/max/select become copies of the
  // kept input, and instructions whose results are no longer read are dropped.
  // choices.size() == size(); returns this tape itself (shared) when nothing changes.
  TapePtr prune(const std::vector<Choice>& choices, const TapePtr& self) const;

 private:
  Tape() = default;
  uint32_t numVars_ = 0, numRegs_ = 0, result_ = 0, numChoices_ = 0;
  std::shared_ptr<const std::vector<double>> uniforms_;
  std::shared_ptr<const std::vector<ExtremumEntry>> extrema_;
  std::shared_ptr<const std::vector<std::shared_ptr<const FieldFunction>>> fields_;
  std::vector<Instr> code_;
  std::vector<uint32_t> sinCos_;
  TapePtr root_;  // the compiled tape this one was pruned from (keeps uniforms alive)
  uint64_t id_ = 0;
  friend struct TapeBuilder;
};

}  // namespace frep
