// Baseline for evaluator benchmarks: the naive interpreter a first F-rep system would write.
// It walks the expression DAG recursively with a switch per node (through applyOp) and no
// memoisation, so a shared sub-expression is evaluated once per path that reaches it.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::bench {

inline double treeWalk(const Node& n, const double* x) {
  switch (n.op) {
    case Op::Const: return n.value;
    case Op::Var: return x[n.index];
    default: break;
  }
  const int arity = opArity(n.op);
  const double a = treeWalk(*n.args[0], x);
  const double b = arity > 1 ? treeWalk(*n.args[1], x) : 0.0;
  const double c = arity > 2 ? treeWalk(*n.args[2], x) : 0.0;
  return applyOp(n.op, a, b, c, n.value);
}

// Number of node visits treeWalk makes (the size of the DAG unfolded into a tree).
inline size_t treeSize(const Node& n) {
  size_t s = 1;
  for (int i = 0; i < opArity(n.op); ++i) s += treeSize(*n.args[i]);
  return s;
}

// A second, fairer baseline: the same recursive walk, but each DAG node is evaluated once per
// point (an interpreter that calls R-functions with already evaluated arguments, as HyperFun's
// does). Values are cached in per-node slots stamped with the point number.
class MemoWalker {
 public:
  explicit MemoWalker(const Expr& e) : root_(&e.node()) {
    forEachNode(e, [&](const Node& n) { slot_.emplace(&n, uint32_t(slot_.size())); });
    value_.resize(slot_.size());
    stamp_.assign(slot_.size(), 0);
  }
  double eval(const double* x) {
    ++point_;
    return walk(*root_, x);
  }

 private:
  double walk(const Node& n, const double* x) {
    if (n.op == Op::Const) return n.value;
    if (n.op == Op::Var) return x[n.index];
    const uint32_t s = slot_.find(&n)->second;
    if (stamp_[s] == point_) return value_[s];
    const int arity = opArity(n.op);
    const double a = walk(*n.args[0], x);
    const double b = arity > 1 ? walk(*n.args[1], x) : 0.0;
    const double c = arity > 2 ? walk(*n.args[2], x) : 0.0;
    stamp_[s] = point_;
    return value_[s] = applyOp(n.op, a, b, c, n.value);
  }
  const Node* root_;
  std::unordered_map<const Node*, uint32_t> slot_;
  std::vector<double> value_;
  std::vector<uint64_t> stamp_;
  uint64_t point_ = 0;
};

}  // namespace frep::bench
