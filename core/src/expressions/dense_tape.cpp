// DenseTape and its one-pass simplifier (dense_tape.h).
//
// The backward pass follows each value from its last reader to its definition, so a register is
// allocated when a value's last reader is met and freed at its definition (linear scan in
// reverse); an instruction's output register may then serve one of its inputs, which the
// evaluators' lane loops allow (each lane reads before it writes).
#include "frep/expressions/dense_tape.h"

#include <algorithm>
#include <stdexcept>

namespace frep {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

bool inSubset(const Instr& ins) {
  switch (ins.op) {
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Neg:
    case Op::Abs:
    case Op::Sqrt:
    case Op::Min:
    case Op::Max:
    case Op::Copy:
      return true;
    case Op::PowI:
      return ins.imm == 2.0;
    default:
      return false;
  }
}

inline bool binary(Op op) { return op == Op::Add || op == Op::Sub || op == Op::Mul || op == Op::Min || op == Op::Max; }

}  // namespace

bool DenseTape::supports(const Tape& t) {
  if (t.hasExtrema()) return false;
  for (const Instr& ins : t.code())
    if (!inSubset(ins)) return false;
  return true;
}

void DenseTape::assign(const Tape& t) {
  if (!supports(t)) throw std::invalid_argument("DenseTape: the tape has ops outside the arithmetic subset");
  code.clear();
  numChoices = 0;
  for (const Instr& ins : t.code()) {
    code.push_back(DenseInstr{ins.op, ins.out, ins.a, binary(ins.op) ? ins.b : ins.a});
    numChoices += ins.op == Op::Min || ins.op == Op::Max;
  }
  numRegs = t.numRegs();
  result = t.resultReg();
  numUniforms = t.numUniforms();
  numVars = t.numVars();
}

void DenseSimplifier::simplify(const DenseTape& parent, const uint8_t* choices, DenseTape& out, size_t stride) {
  const uint32_t fixed = parent.firstTemp();
  if (bind_.size() < parent.numRegs) bind_.resize(parent.numRegs);
  if (free_.size() < size_t(parent.numRegs) + 1) free_.resize(size_t(parent.numRegs) + 1);
  uint32_t* bind = bind_.data();
  uint32_t* freeRegs = free_.data();
  // Constants and vars are bound to themselves, and no call rebinds them: entered once (a
  // pruned tape of Prospero walks ~250 instructions but has ~1,300 constants).
  for (uint32_t r = boundFixed_; r < fixed; ++r) bind[r] = r;
  boundFixed_ = fixed;  // entries past it are temporaries of this call
  std::fill(bind + fixed, bind + parent.numRegs, kNone);
  size_t numFree = 0;
  uint32_t next = fixed;
  auto alloc = [&]() -> uint32_t { return numFree ? freeRegs[--numFree] : next++; };
  auto use = [&](uint32_t p) -> uint32_t {  // register of the value parent register p holds here
    uint32_t& b = bind[p];
    if (b == kNone) b = alloc();
    return b;
  };
  // Written back to front: at most one instruction per parent instruction, plus the result's copy.
  const size_t cap = parent.code.size() + 1;
  if (scratch_.size() < cap) scratch_.resize(cap);
  DenseInstr* const end = scratch_.data() + cap;
  DenseInstr* dst = end;
  uint32_t choicesLeft = 0;
  // The result always lives in a temporary (a copy if the parent's is a constant or a var).
  const uint32_t res = alloc();
  if (parent.result < fixed) {
    *--dst = DenseInstr{Op::Copy, res, parent.result, parent.result};
  } else {
    bind[parent.result] = res;
  }
  const DenseInstr* code = parent.code.data();
  for (size_t i = parent.code.size(); i-- > 0;) {
    const DenseInstr ins = code[i];
    const uint32_t r = bind[ins.out];
    if (r == kNone) continue;  // not read again
    bind[ins.out] = kNone;     // earlier readers of this register read an older value
    const bool choice = ins.op == Op::Min || ins.op == Op::Max;
    if (choice && choices[i * stride] != 0) {
      const uint32_t kept = choices[i * stride] == 1 ? ins.a : ins.b;
      if (bind[kept] == kNone) {
        bind[kept] = r;  // the kept value is computed straight into r
      } else {
        *--dst = DenseInstr{Op::Copy, r, bind[kept], bind[kept]};
        freeRegs[numFree++] = r;
      }
      continue;
    }
    freeRegs[numFree++] = r;
    const uint32_t a = use(ins.a);
    const uint32_t b = binary(ins.op) ? use(ins.b) : a;
    *--dst = DenseInstr{ins.op, r, a, b};
    choicesLeft += choice;
  }
  out.code.assign(dst, end);  // within its capacity once warm
  out.numChoices = choicesLeft;
  out.numRegs = next;
  out.result = res;
  out.numUniforms = parent.numUniforms;
  out.numVars = parent.numVars;
}

}  // namespace frep
