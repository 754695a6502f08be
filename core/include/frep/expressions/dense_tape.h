// A tape of the arithmetic subset (+ - * neg abs sqrt square min max copy) in a compact form for
// quadtree subdivision (frep/sampling/plane.h): 16-byte instructions, and a simplifier that
// prunes it in one backward pass over an interval pass's choices, dropping dead code and
// renumbering the temporaries (Fidget's "tape simplification"), into a tape the caller reuses.
// A pruned tape then reads a few dozen registers, not the root's thousands, and its batches
// stay in L1.
//
// Register layout, as in Tape: [0, numUniforms) constants (the root's uniforms), then the vars,
// then temporaries; constants and vars are never written.
#pragma once

#include <cstdint>
#include <vector>

#include "frep/expressions/tape.h"

namespace frep {

struct DenseInstr {
  Op op;  // Add Sub Mul Neg Abs Sqrt PowI (squares only) Min Max Copy
  uint32_t out = 0, a = 0, b = 0;
};

struct DenseTape {
  std::vector<DenseInstr> code;
  uint32_t numRegs = 0, result = 0;
  uint32_t numUniforms = 0, numVars = 0;
  uint32_t numChoices = 0;  // min/max instructions

  // Whether every instruction of t is in the subset (no extremum, field, select, ...).
  static bool supports(const Tape& t);
  // The whole of t (supports(t) must hold), with t's own registers.
  void assign(const Tape& t);
  uint32_t firstTemp() const { return numUniforms + numVars; }
  size_t size() const { return code.size(); }
};

// Choice per instruction of the tape an interval pass walked: 0 both, 1 keep a, 2 keep b (only
// min/max entries are read).
class DenseSimplifier {
 public:
  // out = parent restricted to where the choices hold: a decided min/max becomes its kept
  // operand (renamed, or a copy when that value already has a register), unread instructions
  // are dropped, temporaries are reallocated last use first (so a tape needs few registers).
  // The values are the parent's bit for bit: the same operations on the same operands.
  // choices[k * stride]: instruction k's (a stride of 4 reads one box of eval4's).
  void simplify(const DenseTape& parent, const uint8_t* choices, DenseTape& out, size_t stride = 1);
  // The same for the four boxes of one eval4 pass (choices[4 k + j]: box j's choice at
  // instruction k): *out[j] for each j set in `wanted` (bits 0-3) gets the instructions
  // simplify(parent, choices + j, *out[j], 4) keeps, in the same order on the same operands
  // (the same values, bit for bit), each in a register of its own and without the copies. One
  // branch-free backward pass finds the live instructions of the four boxes at once, then one
  // forward pass per box over them alone renames the registers, also without a branch.
  void simplify4(const DenseTape& parent, const uint8_t* choices, unsigned wanted, DenseTape* const out[4]);

 private:
  void forward(const DenseTape& parent, const uint32_t* live, size_t n, DenseTape& out);
  std::vector<uint32_t> bind_;  // parent register -> out register of its live value
  uint32_t boundFixed_ = 0;     // bind_[r] == r for r below it
  std::vector<uint32_t> free_;
  std::vector<DenseInstr> scratch_;  // the simplified code, written back to front
  // simplify4: per parent register, byte j set when box j reads it later; per box, its live
  // instructions (last first) with their choices (index | choice << 30).
  std::vector<uint32_t> live4_;
  std::vector<uint32_t> lists_;
  std::vector<uint32_t> map_;  // forward: parent register -> out register of its value
  uint32_t mapFixed_ = 0;      // map_[r] == r for r below it
};

}  // namespace frep
