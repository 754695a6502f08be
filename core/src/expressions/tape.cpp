// DAG -> tape compilation (topological order, linear-scan register reuse) and tape pruning.
#include "frep/expressions/tape.h"

#include "frep/extremum/extremum.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <stdexcept>
#include <unordered_map>

namespace frep {

namespace {
std::atomic<uint64_t> gNextTapeId{1};
bool isChoiceOp(Op op) { return op == Op::Min || op == Op::Max || op == Op::Select; }

// Tape::sinCosPlan. A Sin/Cos at k and the complementary Cos/Sin at j > k reading the same
// register r can both be computed at k when, strictly between k and j, nothing writes r (j
// would read the same value) and nothing reads or writes out_j (it is written early, at k);
// k must not overwrite r itself, and the two outputs must differ. Checking each pair against the
// original tape stays right when pairs overlap: then one pair lies inside the other's window or
// each has an instruction inside the other's, and those instructions' reads and writes were
// checked. No pair spans an Extremum (its inputs are not in a/b/c). One forward pass.
std::vector<uint32_t> planSinCos(const std::vector<Instr>& code, uint32_t numRegs) {
  std::vector<uint32_t> plan;
  bool hasSin = false, hasCos = false;
  for (const Instr& ins : code) {
    hasSin |= ins.op == Op::Sin;
    hasCos |= ins.op == Op::Cos;
  }
  if (!hasSin || !hasCos) return plan;
  constexpr uint32_t kNone = UINT32_MAX;
  // pending[r][op == Cos]: the latest unpaired Sin / Cos reading r since r was last written
  std::vector<std::array<uint32_t, 2>> pending(numRegs, {kNone, kNone});
  std::vector<size_t> lastTouch(numRegs, 0);  // 1 + the last instruction reading or writing it
  size_t barrier = 0;                         // pairs start at or after the last Extremum
  for (size_t i = 0; i < code.size(); ++i) {
    const Instr& ins = code[i];
    if (ins.op == Op::Extremum) {
      barrier = i + 1;
      lastTouch[ins.out] = i + 1;
      continue;
    }
    const bool trig = ins.op == Op::Sin || ins.op == Op::Cos;
    const int slot = ins.op == Op::Cos;
    bool paired = false;
    if (trig) {
      const uint32_t k = pending[ins.a][1 - slot];
      if (k != kNone && k >= barrier && code[k].out != ins.out && lastTouch[ins.out] <= k + 1) {
        if (plan.empty()) plan.assign(code.size(), Tape::kNoSinCos);
        plan[k] = ins.out;
        plan[i] = Tape::kSinCosDone;
        pending[ins.a][1 - slot] = kNone;
        paired = true;
      }
    }
    const int arity = opArity(ins.op);
    if (arity > 0) lastTouch[ins.a] = i + 1;
    if (arity > 1) lastTouch[ins.b] = i + 1;
    if (arity > 2) lastTouch[ins.c] = i + 1;
    lastTouch[ins.out] = i + 1;
    pending[ins.out] = {kNone, kNone};
    if (trig && !paired && ins.out != ins.a) pending[ins.a][slot] = uint32_t(i);
  }
  return plan;
}
}  // namespace

struct TapeBuilder {
  static TapePtr make() { return TapePtr(new Tape()); }
  static Tape& mut(const TapePtr& t) { return const_cast<Tape&>(*t); }
};

TapePtr Tape::compile(const Expr& e, uint32_t nvars) {
  // 1. Topological order of the distinct nodes (children first).
  std::vector<const Node*> order;
  forEachNode(e, [&](const Node& n) { order.push_back(&n); });

  nvars = std::max(nvars, frep::numVars(e));
  auto uniforms = std::make_shared<std::vector<double>>();
  std::unordered_map<const Node*, uint32_t> constReg;
  std::unordered_map<const Node*, size_t> position;
  for (size_t i = 0; i < order.size(); ++i) {
    const Node* n = order[i];
    position[n] = i;
    if (n->op == Op::Param)
      throw std::invalid_argument("Tape::compile: parameter a[" + std::to_string(n->index + 1) +
                                  "] is not bound (call bindParams first)");
    if (n->op == Op::Const) {
      constReg[n] = static_cast<uint32_t>(uniforms->size());
      uniforms->push_back(n->value);
    }
  }
  const uint32_t nu = static_cast<uint32_t>(uniforms->size());

  // 2. Last reader of each node.
  std::unordered_map<const Node*, size_t> lastUse;
  for (size_t i = 0; i < order.size(); ++i)
    for (size_t k = 0; k < numChildren(*order[i]); ++k) lastUse[&child(*order[i], k)] = i;
  auto extrema = std::make_shared<std::vector<ExtremumEntry>>();

  // 3. Linear-scan allocation of temporaries; inputs whose last use is this instruction are
  //    freed before the output is allocated, so an output may reuse an input's register.
  std::unordered_map<const Node*, uint32_t> reg;
  std::vector<uint32_t> freeRegs;
  uint32_t next = nu + nvars;
  TapePtr tape = TapeBuilder::make();
  Tape& t = TapeBuilder::mut(tape);
  auto regOf = [&](const Node* n) -> uint32_t {
    if (n->op == Op::Const) return constReg.at(n);
    if (n->op == Op::Var) return nu + n->index;
    return reg.at(n);
  };
  for (size_t i = 0; i < order.size(); ++i) {
    const Node* n = order[i];
    const int arity = static_cast<int>(numChildren(*n));
    if (arity == 0 && n->op != Op::Extremum) continue;
    Instr ins;
    ins.op = n->op;
    ins.imm = n->value;
    if (n->op == Op::Extremum) {
      ExtremumEntry entry;
      entry.spec = n->spec;
      for (const Expr& in : n->spec->inputs) entry.inputRegs.push_back(regOf(&in.node()));
      entry.body = Tape::compile(n->spec->body, n->spec->outer() + n->spec->hidden);
      ins.a = static_cast<uint32_t>(extrema->size());
      extrema->push_back(std::move(entry));
    } else {
      uint32_t in[3] = {0, 0, 0};
      for (int k = 0; k < arity; ++k) in[k] = regOf(n->args[k].get());
      ins.a = in[0];
      ins.b = in[1];
      ins.c = in[2];
    }
    for (int k = 0; k < arity; ++k) {
      const Node* ch = &child(*n, static_cast<size_t>(k));
      if (ch->op == Op::Const || ch->op == Op::Var) continue;
      if (lastUse.at(ch) == i && reg.count(ch)) {
        freeRegs.push_back(reg.at(ch));
        reg.erase(ch);
      }
    }
    uint32_t out;
    if (!freeRegs.empty()) {
      // lowest free register keeps the file compact and the allocation deterministic
      auto it = std::min_element(freeRegs.begin(), freeRegs.end());
      out = *it;
      freeRegs.erase(it);
    } else {
      out = next++;
    }
    ins.out = out;
    reg[n] = out;
    if (isChoiceOp(n->op)) ++t.numChoices_;
    t.code_.push_back(ins);
  }
  t.numVars_ = nvars;
  t.numRegs_ = next;
  t.uniforms_ = uniforms;
  t.extrema_ = extrema;
  t.result_ = regOf(&e.node());
  t.sinCos_ = planSinCos(t.code_, t.numRegs_);
  t.id_ = gNextTapeId++;
  return tape;
}

TapePtr Tape::prune(const std::vector<Choice>& choices, const TapePtr& self) const {
  if (choices.size() != code_.size()) throw std::invalid_argument("Tape::prune: choice count");
  bool any = false;
  for (size_t i = 0; i < code_.size(); ++i)
    if (choices[i] != Choice::Both && isChoiceOp(code_[i].op)) any = true;
  if (!any) return self;

  // Rewrite decided instructions into copies, then drop what is no longer read. Walking
  // backwards with the set of registers still needed is exact even with register reuse,
  // because every instruction's write kills the register's previous value.
  std::vector<Instr> code = code_;
  for (size_t i = 0; i < code.size(); ++i) {
    Instr& ins = code[i];
    if (!isChoiceOp(ins.op) || choices[i] == Choice::Both) continue;
    uint32_t src;
    if (ins.op == Op::Select) src = choices[i] == Choice::KeepA ? ins.b : ins.c;
    else src = choices[i] == Choice::KeepA ? ins.a : ins.b;
    ins = Instr{Op::Copy, ins.out, src, 0, 0, 0.0};
  }
  std::vector<char> needed(numRegs_, 0);
  needed[result_] = 1;
  std::vector<Instr> kept;
  kept.reserve(code.size());
  for (size_t i = code.size(); i-- > 0;) {
    const Instr& ins = code[i];
    if (!needed[ins.out]) continue;
    needed[ins.out] = 0;
    if (ins.op == Op::Extremum) {
      for (uint32_t r : (*extrema_)[ins.a].inputRegs) needed[r] = 1;
      kept.push_back(ins);
      continue;
    }
    int arity = opArity(ins.op);
    if (arity > 0) needed[ins.a] = 1;
    if (arity > 1) needed[ins.b] = 1;
    if (arity > 2) needed[ins.c] = 1;
    kept.push_back(ins);
  }
  std::reverse(kept.begin(), kept.end());

  // A copy into the result register at the very end can be folded away by redirecting the
  // result (saves one pass over the batch).
  uint32_t result = result_;
  while (!kept.empty() && kept.back().op == Op::Copy && kept.back().out == result) {
    result = kept.back().a;
    kept.pop_back();
  }

  TapePtr out = TapeBuilder::make();
  Tape& t = TapeBuilder::mut(out);
  t.numVars_ = numVars_;
  t.numRegs_ = numRegs_;
  t.uniforms_ = uniforms_;
  t.extrema_ = extrema_;
  t.result_ = result;
  t.code_ = std::move(kept);
  for (auto& ins : t.code_)
    if (isChoiceOp(ins.op)) ++t.numChoices_;
  t.sinCos_ = planSinCos(t.code_, t.numRegs_);
  t.root_ = root_ ? root_ : self;
  t.id_ = gNextTapeId++;
  return out;
}

}  // namespace frep
