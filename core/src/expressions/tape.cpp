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
  auto fields = std::make_shared<std::vector<std::shared_ptr<const FieldFunction>>>();

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
      if (n->op == Op::Field) {
        ins.imm = double(fields->size());
        fields->push_back(n->fn);
      }
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
  t.fields_ = fields;
  t.result_ = regOf(&e.node());
  t.sinCos_ = planSinCos(t.code_, t.numRegs_);
  t.id_ = gNextTapeId++;
  return tape;
}

// Tape::prune in one forward and one backward pass over reused per-thread buffers (interval
// subdivision prunes once per box, so this runs millions of times).
//
// Forward: a decided min/max/select is a copy of its kept input, and later readers of its output
// read the copy's source directly, as long as the source register still holds that value.
// Registers are reused, so a copy is only postponed: just before an instruction overwrites a
// source register, the copies still depending on it are emitted (and an extremum's input
// registers, which its shared table names, always get their values first).
// Backward: instructions whose results are no longer read are dropped; walking backwards with
// the set of registers still needed is exact even with register reuse, because every
// instruction's write kills the register's previous value.
namespace {
struct PruneScratch {
  // Per register, valid only where its stamp equals the current prune's (no O(registers) reset
  // per prune: a tape may have thousands of registers and a pruned one a few dozen instructions).
  std::vector<uint32_t> alias;   // register whose value r holds (else r itself)
  std::vector<int32_t> head;     // first node of r's dependents list (else none)
  std::vector<uint32_t> stamp;   // alias/head valid
  std::vector<uint32_t> needed;  // == stamp value: still read by a later kept instruction
  uint32_t gen = 0;
  std::vector<std::pair<uint32_t, int32_t>> nodes;  // (dependent, next); stale entries skipped
  std::vector<Instr> fwd, kept;

  void reserve(uint32_t numRegs) {
    if (stamp.size() < numRegs)
      alias.resize(numRegs), head.resize(numRegs), stamp.resize(numRegs, 0), needed.resize(numRegs, 0);
  }
  // A new stamp: everything stamped before reads as unset.
  uint32_t fresh() {
    if (++gen == 0) {  // wrapped: clear once every 2^32 stamps
      std::fill(stamp.begin(), stamp.end(), 0u), std::fill(needed.begin(), needed.end(), 0u);
      gen = 1;
    }
    return gen;
  }
  uint32_t aliasOf(uint32_t r) const { return stamp[r] == gen ? alias[r] : r; }
  int32_t headOf(uint32_t r) const { return stamp[r] == gen ? head[r] : -1; }
  void set(uint32_t r, uint32_t a, int32_t h) { stamp[r] = gen, alias[r] = a, head[r] = h; }
};
}  // namespace

TapePtr Tape::prune(const std::vector<Choice>& choices, const TapePtr& self) const {
  if (choices.size() != code_.size()) throw std::invalid_argument("Tape::prune: choice count");
  bool any = false;
  for (size_t i = 0; i < code_.size() && !any; ++i)
    any = choices[i] != Choice::Both && isChoiceOp(code_[i].op);
  if (!any) return self;

  thread_local PruneScratch sc;
  sc.reserve(numRegs_);

  // Backward: keep what the result still reads (into `to`, in order); `from` is read in reverse.
  auto dropDead = [&](const std::vector<Instr>& from, std::vector<Instr>& to, uint32_t result) {
    const uint32_t need = sc.fresh();  // needed[r] == need: read by a later kept instruction
    sc.needed[result] = need;
    to.clear();
    for (size_t i = from.size(); i-- > 0;) {
      const Instr& ins = from[i];
      if (sc.needed[ins.out] != need) continue;
      sc.needed[ins.out] = 0;
      if (ins.op == Op::Extremum) {
        for (uint32_t r : (*extrema_)[ins.a].inputRegs) sc.needed[r] = need;
      } else {
        const int arity = opArity(ins.op);
        if (arity > 0) sc.needed[ins.a] = need;
        if (arity > 1) sc.needed[ins.b] = need;
        if (arity > 2) sc.needed[ins.c] = need;
      }
      to.push_back(ins);
    }
    std::reverse(to.begin(), to.end());
  };

  // 1. Decided choices become copies of their kept input; drop what is no longer read.
  sc.fwd.clear();
  for (size_t i = 0; i < code_.size(); ++i) {
    Instr ins = code_[i];
    if (isChoiceOp(ins.op) && choices[i] != Choice::Both) {
      uint32_t src;
      if (ins.op == Op::Select) src = choices[i] == Choice::KeepA ? ins.b : ins.c;
      else src = choices[i] == Choice::KeepA ? ins.a : ins.b;
      ins = Instr{Op::Copy, ins.out, src, 0, 0, 0.0};
    }
    sc.fwd.push_back(ins);
  }
  dropDead(sc.fwd, sc.kept, result_);

  // 2. Forward the copies to their readers.
  sc.fresh();
  sc.nodes.clear();
  bool settled = false;
  auto settle = [&](uint32_t x) {  // x gets its own value
    const uint32_t a = sc.aliasOf(x);
    if (a == x) return;
    sc.fwd.push_back(Instr{Op::Copy, x, a, 0, 0, 0.0});
    sc.set(x, x, sc.headOf(x));
    settled = true;
  };
  auto overwrite = [&](uint32_t r) {  // r is about to be written
    for (int32_t n = sc.headOf(r); n >= 0; n = sc.nodes[size_t(n)].second)
      if (sc.aliasOf(sc.nodes[size_t(n)].first) == r) settle(sc.nodes[size_t(n)].first);
    sc.set(r, r, -1);  // whatever r aliased, it now gets a value of its own
  };
  sc.fwd.clear();
  for (Instr ins : sc.kept) {
    if (ins.op == Op::Extremum) {
      for (uint32_t r : (*extrema_)[ins.a].inputRegs) settle(r);
      overwrite(ins.out);
      sc.fwd.push_back(ins);
      continue;
    }
    const int arity = opArity(ins.op);
    if (arity > 0) ins.a = sc.aliasOf(ins.a);
    if (arity > 1) ins.b = sc.aliasOf(ins.b);
    if (arity > 2) ins.c = sc.aliasOf(ins.c);
    overwrite(ins.out);
    if (ins.op == Op::Copy) {
      if (ins.a != ins.out) {
        sc.alias[ins.out] = ins.a;  // stamped by overwrite
        sc.nodes.emplace_back(ins.out, sc.headOf(ins.a));
        sc.set(ins.a, sc.aliasOf(ins.a), int32_t(sc.nodes.size() - 1));
      }
      continue;
    }
    sc.fwd.push_back(ins);
  }
  const uint32_t result = sc.aliasOf(result_);
  // 3. A copy emitted because its source was about to be overwritten may not be read again.
  if (settled) dropDead(sc.fwd, sc.kept, result);
  else sc.kept.swap(sc.fwd);

  TapePtr out = TapeBuilder::make();
  Tape& t = TapeBuilder::mut(out);
  t.numVars_ = numVars_;
  t.numRegs_ = numRegs_;
  t.uniforms_ = uniforms_;
  t.extrema_ = extrema_;
  t.fields_ = fields_;
  t.result_ = result;
  t.code_ = sc.kept;
  for (auto& ins : t.code_)
    if (isChoiceOp(ins.op)) ++t.numChoices_;
  t.sinCos_ = planSinCos(t.code_, t.numRegs_);
  t.root_ = root_ ? root_ : self;
  t.id_ = gNextTapeId++;
  return out;
}

}  // namespace frep
