// DenseTape and its one-pass simplifier (dense_tape.h).
//
// The backward pass follows each value from its last reader to its definition, so a register is
// allocated when a value's last reader is met and freed at its definition (linear scan in
// reverse); an instruction's output register may then serve one of its inputs, which the
// evaluators' lane loops allow (each lane reads before it writes).
#include "frep/expressions/dense_tape.h"

#include <algorithm>
#include <cstring>
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

// Liveness for four boxes at once, without a branch: live4_[r] holds one byte per box, 1 when a
// later live instruction of that box reads register r (or r holds the result). Walking back, an
// instruction is live for box j when its output's byte is; it clears that byte and sets its
// operands' (a decided min/max only its kept operand's), and its index, with box j's choice
// there in the top two bits, is appended to box j's list, whose count advances by the live
// byte. These are the instructions simplify's backward pass keeps ("not read again" drops the
// others), met in the same order.
void DenseSimplifier::simplify4(const DenseTape& parent, const uint8_t* choices, unsigned wanted,
                                DenseTape* const out[4]) {
  const size_t size = parent.code.size();
  if (size >= (size_t(1) << 30)) {  // no room for the choice beside the index (never in practice)
    for (size_t j = 0; j < 4; ++j)
      if ((wanted >> j) & 1u) simplify(parent, choices + j, *out[j], 4);
    return;
  }
  if (live4_.size() < parent.numRegs) live4_.resize(parent.numRegs);
  if (lists_.size() < 4 * size) lists_.resize(4 * size);
  uint32_t* live = live4_.data();
  std::fill(live + parent.firstTemp(), live + parent.numRegs, 0u);
  uint32_t want = 0;
  for (int j = 0; j < 4; ++j) want |= uint32_t((wanted >> j) & 1u) << (8 * j);
  // A constant or var result reads no instruction (the bytes of constants and vars are set
  // below too, and never read: no instruction writes them).
  if (parent.result >= parent.firstTemp()) live[parent.result] = want;
  uint32_t* lists[4];
  for (size_t j = 0; j < 4; ++j) lists[j] = lists_.data() + j * size;
  size_t n0 = 0, n1 = 0, n2 = 0, n3 = 0;
  const DenseInstr* code = parent.code.data();
  for (size_t i = size; i-- > 0;) {
    const DenseInstr& ins = code[i];
    const uint32_t l = live[ins.out];
    live[ins.out] = 0;
    uint32_t c;
    std::memcpy(&c, choices + 4 * i, sizeof c);
    const uint32_t isChoice = ins.op == Op::Min || ins.op == Op::Max ? 0x01010101u : 0u;
    const uint32_t keepA = c & isChoice, keepB = (c >> 1) & isChoice;  // bytes of 1 (a) or 2 (b)
    live[ins.a] |= l & ~keepB;
    live[ins.b] |= l & ~keepA;  // (a unary op's b is its a)
    // Each entry: the index, and the box's choice there (0 for other ops) in the top two bits.
    const uint32_t cc = c & (isChoice * 3u), at = uint32_t(i);
    lists[0][n0] = at | (cc << 30), n0 += l & 1u;
    lists[1][n1] = at | ((cc >> 8) << 30), n1 += (l >> 8) & 1u;
    lists[2][n2] = at | ((cc >> 16) << 30), n2 += (l >> 16) & 1u;
    lists[3][n3] = at | ((cc >> 24) << 30), n3 += l >> 24;
  }
  const size_t counts[4] = {n0, n1, n2, n3};
  for (size_t j = 0; j < 4; ++j)
    if ((wanted >> j) & 1u) forward(parent, lists[j], counts[j], *out[j]);
}

// The live instructions of one box in tape order (live[n - 1] first), each output in a new
// temporary (static single assignment: no register is written twice), so a decided min/max
// always hands its kept value's register on and no copy is ever needed, and no step waits for
// a register allocation: every step is a select.
void DenseSimplifier::forward(const DenseTape& parent, const uint32_t* live, size_t n, DenseTape& out) {
  const uint32_t fixed = parent.firstTemp();
  if (map_.size() < parent.numRegs) map_.resize(parent.numRegs);
  uint32_t* map = map_.data();
  // Constants and vars map to themselves, entered once as in simplify (a temporary's entry is
  // always written before it is read).
  for (uint32_t r = mapFixed_; r < fixed; ++r) map[r] = r;
  mapFixed_ = fixed;
  if (scratch_.size() < n + 1) scratch_.resize(n + 1);
  DenseInstr* dst = scratch_.data();
  uint32_t next = fixed, choicesLeft = 0;
  const DenseInstr* code = parent.code.data();
  for (size_t m = n; m-- > 0;) {
    const uint32_t e = live[m];
    const DenseInstr ins = code[e & 0x3fffffffu];
    const uint32_t a = map[ins.a], b = map[ins.b];
    const bool choice = ins.op == Op::Min || ins.op == Op::Max;
    const uint32_t c = e >> 30;
    const bool decided = c != 0;
    *dst = DenseInstr{ins.op, next, a, b};
    dst += !decided;
    map[ins.out] = decided ? (c == 1 ? a : b) : next;
    next += !decided;
    choicesLeft += choice & !decided;
  }
  uint32_t res = map[parent.result];
  if (res < fixed) {  // the result always lives in a temporary
    *dst++ = DenseInstr{Op::Copy, next, res, res};
    res = next++;
  }
  out.code.assign(scratch_.data(), dst);
  out.numChoices = choicesLeft;
  out.numRegs = next;
  out.result = res;
  out.numUniforms = parent.numUniforms;
  out.numVars = parent.numVars;
}

}  // namespace frep
