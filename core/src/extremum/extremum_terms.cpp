// The search objective as a min of terms: constraint propagation against the branch-and-bound
// cut, centred (mean-value) upper bounds and local ascent (see extremum_terms.h).
#include "extremum/extremum_terms.h"
#include "evaluators/interval_fast.h"
#include "frep/expressions/sin_cos.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include "extremum/term_intervals.h"
#include "extremum/term_step_grad.h"

namespace frep {
namespace detail {

namespace {

template <typename Make>
std::vector<Expr> product(const Expr& e, const std::vector<Expr>& a, const std::vector<Expr>& b, Make make) {
  if (a.size() * b.size() > kMaxTerms) return {e};
  std::vector<Expr> out;
  for (const Expr& x : a)
    for (const Expr& y : b) out.push_back(make(x, y));
  return out;
}

// The terms of e under min (isMin: e == min of them) or max: min (max) itself concatenates,
// +, - and negation distribute (a max under a minus or a negation gives min terms), and, under
// max, |a| = max(a, -a).
std::vector<Expr> splitTerms(const Expr& e, bool isMin) {
  const Node& nd = e.node();
  if (nd.op == (isMin ? Op::Min : Op::Max)) {
    std::vector<Expr> a = splitTerms(e.arg(0), isMin), b = splitTerms(e.arg(1), isMin);
    if (a.size() + b.size() > kMaxTerms) return {e};
    a.insert(a.end(), b.begin(), b.end());
    return a;
  }
  switch (nd.op) {
    case Op::Abs:
      if (isMin) return {e};
      return {e.arg(0), -e.arg(0)};
    case Op::Add:
      return product(e, splitTerms(e.arg(0), isMin), splitTerms(e.arg(1), isMin),
                     [](const Expr& x, const Expr& y) { return x + y; });
    case Op::Sub:
      return product(e, splitTerms(e.arg(0), isMin), splitTerms(e.arg(1), !isMin),
                     [](const Expr& x, const Expr& y) { return x - y; });
    case Op::Neg: {
      std::vector<Expr> out;
      for (const Expr& t : splitTerms(e.arg(0), !isMin)) out.push_back(-t);
      return out;
    }
    default:
      return {e};
  }
}

}  // namespace

std::vector<Expr> minTerms(const Expr& e) { return splitTerms(e, true); }
std::vector<Expr> maxTerms(const Expr& e) { return splitTerms(e, false); }

void TermForm::build(const Expr& objective, uint32_t n, uint32_t p, const std::vector<Expr>& uOfT) {
  n_ = n;
  p_ = p;
  ok_ = false;
  nodes_.clear();
  terms_.clear();
  dep_.clear();
  indep_.clear();
  bool bad = false;
  forEachNode(objective, [&](const Node& nd) {
    if (nd.op == Op::Extremum || nd.op == Op::Field || nd.op == Op::Param) bad = true;
  });
  if (bad || p == 0) return;
  std::vector<Expr> vars;
  for (uint32_t i = 0; i < n; ++i) vars.push_back(Expr::x(i));
  for (const Expr& u : uOfT) vars.push_back(u);
  const std::vector<Expr> ts = minTerms(remap(objective, vars));
  std::unordered_map<const Node*, int32_t> index;
  std::function<int32_t(const NodePtr&)> visit = [&](const NodePtr& np) -> int32_t {
    auto it = index.find(np.get());
    if (it != index.end()) return it->second;
    Nd q;
    q.op = np->op;
    const int ar = opArity(np->op);
    if (ar >= 1) q.a = visit(np->args[0]);
    if (ar >= 2) q.b = visit(np->args[1]);
    if (ar >= 3) q.c = visit(np->args[2]);
    q.imm = np->value;
    q.var = np->index;
    q.square = q.op == Op::Mul && q.a == q.b;
    if (np->op == Op::Var) q.dep = np->index >= n && np->index < n + p;
    for (int32_t in : {q.a, q.b, q.c})
      if (in >= 0 && nodes_[size_t(in)].dep) q.dep = true;
    nodes_.push_back(q);
    const int32_t id = int32_t(nodes_.size() - 1);
    index.emplace(np.get(), id);
    return id;
  };
  for (const Expr& t : ts) terms_.push_back(visit(t.ptr()));
  varNode_.assign(p, UINT32_MAX);
  for (size_t k = 0; k < nodes_.size(); ++k) (nodes_[k].dep ? dep_ : indep_).push_back(uint32_t(k));
  val_.assign(nodes_.size() + 1, Interval());  // + the zero slot (the steps' missing operands)
  valC_.resize(nodes_.size());
  der_.resize(nodes_.size() * p);
  con_.resize(nodes_.size());
  for (size_t k = 0; k < nodes_.size(); ++k)
    if (nodes_[k].op == Op::Var && nodes_[k].dep) varNode_[nodes_[k].var - n] = uint32_t(k);
  pv_.assign(nodes_.size() + 1, 0.0);  // + the zero slot
  pd_.assign((nodes_.size() + 1) * p, 0.0);
  const uint32_t zero = uint32_t(nodes_.size());
  steps_.clear();
  for (uint32_t k : dep_) {
    const Nd& q = nodes_[k];
    Step st;
    st.op = q.op;
    st.k = k;
    st.imm = q.imm;
    st.square = q.square;
    if (q.op == Op::Var) {
      st.var = q.var - n;
    } else {
      st.a = q.a >= 0 ? uint32_t(q.a) : zero;
      st.b = q.b >= 0 ? uint32_t(q.b) : zero;
      st.c = q.c >= 0 ? uint32_t(q.c) : zero;
      st.depA = q.a >= 0 && nodes_[size_t(q.a)].dep;
      st.depB = q.b >= 0 && nodes_[size_t(q.b)].dep;
    }
    steps_.push_back(st);
  }
  // Steps whose gradient is the same at every point (affine in t, constant coefficients: the
  // u = X - t kind of node) get it once here, by pointGrad's own arithmetic; pointGrad then
  // only updates their values.
  std::vector<char> constant(nodes_.size() + 1, 0);
  for (size_t k = 0; k < nodes_.size(); ++k)
    if (nodes_[k].op == Op::Const) pv_[k] = nodes_[k].imm;  // as setX
  for (Step& st : steps_) {
    const bool okA = !st.depA || constant[st.a], okB = !st.depB || constant[st.b];
    auto isConst = [&](uint32_t i) { return i < nodes_.size() && nodes_[i].op == Op::Const; };
    switch (st.op) {
      case Op::Var: st.constGrad = true; break;
      case Op::Neg: case Op::Copy: st.constGrad = okA; break;
      case Op::Add: case Op::Sub: st.constGrad = okA && okB; break;
      case Op::Mul:
        st.constGrad = !st.square && ((st.depA && !st.depB && isConst(st.b) && okA) || (st.depB && !st.depA && isConst(st.a) && okB));
        break;
      default: break;
    }
    constant[st.k] = st.constGrad;
    if (!st.constGrad) continue;
    if (st.op == Op::Var) {
      for (uint32_t j = 0; j < p; ++j) pd_[size_t(st.k) * p + j] = j == st.var ? 1.0 : 0.0;
    } else {
      stepGrad<0>(st, pv_[st.a], pv_[st.b], 0.0);  // the values these partials read are constants
    }
  }
  ok_ = true;
}

void TermForm::setX(const double* X) {
  const Interval everything = Interval::everything();
  for (uint32_t k : indep_) {
    const Nd& q = nodes_[k];
    Interval v;
    double d;
    if (q.op == Op::Const) {
      v = std::isnan(q.imm) ? everything : Interval(q.imm);
      d = q.imm;
    } else if (q.op == Op::Var) {
      v = q.var < n_ ? Interval(X[q.var]) : everything;
      d = q.var < n_ ? X[q.var] : std::nan("");
    } else {
      v = ival(q.op, val_[size_t(q.a)], q.b >= 0 ? val_[size_t(q.b)] : Interval(),
                        q.c >= 0 ? val_[size_t(q.c)] : Interval(), q.imm, q.square);
      d = applyOp(q.op, pv_[size_t(q.a)], q.b >= 0 ? pv_[size_t(q.b)] : 0.0, q.c >= 0 ? pv_[size_t(q.c)] : 0.0, q.imm);
    }
    val_[k] = valC_[k] = v;
    pv_[k] = d;
  }
}

void TermForm::evalValues(const double* tlo, const double* thi) {
  Interval* val = val_.data();
  for (const Step& q : steps_) {
    if (q.op == Op::Var) val[q.k] = Interval(tlo[q.var], thi[q.var]);
    else val[q.k] = ival(q.op, val[q.a], val[q.b], val[q.c], q.imm, q.square);
  }
}

// Backward projection of node k's constraint con_[k] onto its operands (outward rounded, so
// no point satisfying the constraint is lost). False when a constraint becomes empty.
bool TermForm::project(uint32_t k) {
  const Nd& q = nodes_[k];
  const Interval V = con_[k];
  if (q.a < 0) return true;
  Interval& A = con_[size_t(q.a)];
  Interval dummy;
  Interval& B = q.b >= 0 ? con_[size_t(q.b)] : dummy;
  auto square = [&](Interval& a) {
    if (V.hi < 0.0) return false;
    const double sh = up1(std::sqrt(V.hi));
    if (!meet(a, Interval(-sh, sh))) return false;
    if (V.lo > 0.0) return excludeAround0(a, down1(std::sqrt(V.lo)));
    return true;
  };
  switch (q.op) {
    case Op::Copy: return meet(A, V);
    case Op::Neg: return meet(A, ineg(V));
    case Op::Add: return meet(A, isub(V, B)) && meet(B, isub(V, A));
    case Op::Sub: return meet(A, iadd(V, B)) && meet(B, isub(A, V));
    case Op::Mul:
      if (q.square) return square(A);
      if (B.lo > 0.0 || B.hi < 0.0)
        if (!meet(A, applyOp(Op::Div, V, B))) return false;
      if (A.lo > 0.0 || A.hi < 0.0)
        if (!meet(B, applyOp(Op::Div, V, A))) return false;
      return true;
    case Op::PowI:
      if (q.imm == 2.0) return square(A);
      return true;
    case Op::Sqrt:
      if (V.hi < 0.0) return false;
      if (!meetHi(A, up1(V.hi * V.hi))) return false;
      if (V.lo > 0.0) return meetLo(A, down1(V.lo * V.lo));
      return true;
    case Op::Abs:
      if (!meet(A, Interval(-V.hi, V.hi))) return false;
      return excludeAround0(A, V.lo);
    case Op::Min:  // min(a, b) >= lo forces both; <= hi forces the one that can be small
      if (!meetLo(A, V.lo) || !meetLo(B, V.lo)) return false;
      if (A.lo > V.hi) return meetHi(B, V.hi);
      if (B.lo > V.hi) return meetHi(A, V.hi);
      return true;
    case Op::Max:
      if (!meetHi(A, V.hi) || !meetHi(B, V.hi)) return false;
      if (A.hi < V.lo) return meetLo(B, V.lo);
      if (B.hi < V.lo) return meetLo(A, V.lo);
      return true;
    case Op::RAnd:  // RAnd(a, b) <= min(a, b) for -1 < alpha <= 1
      if (!(q.imm > -1.0 && q.imm <= 1.0)) return true;
      if (!meetLo(A, V.lo) || !meetLo(B, V.lo)) return false;
      // Increasing in a: RAnd(a, b) >= theta with b <= B.hi needs a >= its inverse at B.hi.
      return meetLo(A, rAndInverse(V.lo, B.hi, q.imm)) && meetLo(B, rAndInverse(V.lo, A.hi, q.imm));
    case Op::ROr:  // ROr(a, b) >= max(a, b); ROr(a, b) = -RAnd(-a, -b)
      if (!(q.imm > -1.0 && q.imm <= 1.0)) return true;
      if (!meetHi(A, V.hi) || !meetHi(B, V.hi)) return false;
      return meetHi(A, -rAndInverse(-V.hi, -B.lo, q.imm)) && meetHi(B, -rAndInverse(-V.hi, -A.lo, q.imm));
    default:
      return true;
  }
}

bool TermForm::contract(double* tlo, double* thi, double theta, double& ub, double& ub0, uint32_t& passes) {
  // The cut is lowered by a relative margin far above the rounding of the computed body, so
  // that the discarded points have computed values below theta too.
  const bool backward = theta < kInf;
  const double cut = backward ? theta - 1e-9 * (1.0 + std::fabs(theta)) : kInf;
  const size_t K = terms_.size();
  for (int round = 0;; ++round) {
    evalValues(tlo, thi);
    ++passes;
    ub = kInf;
    for (size_t i = 0; i < K; ++i) {
      const double h = val_[size_t(terms_[i])].hi;
      if (!std::isnan(h)) ub = std::min(ub, h);
    }
    if (round == 0) ub0 = ub;
    if (!backward) return true;
    if (ub < cut) return false;
    if (round == 2) return true;
    // backward
    for (size_t k = 0; k < nodes_.size(); ++k) {
      con_[k] = val_[k];
      if (std::isnan(con_[k].lo) || std::isnan(con_[k].hi)) con_[k] = Interval::everything();
    }
    for (size_t i = 0; i < K; ++i)
      if (!meetLo(con_[size_t(terms_[i])], cut)) return false;
    for (size_t k = nodes_.size(); k-- > 0;) {
      const Interval& c = con_[k];
      if (c.lo == val_[k].lo && c.hi == val_[k].hi) continue;  // nothing learnt here
      if (!project(uint32_t(k))) return false;
    }
    ++passes;
    bool shrunk = false;
    for (uint32_t j = 0; j < p_; ++j) {
      if (varNode_[j] == UINT32_MAX) continue;
      const Interval& c = con_[varNode_[j]];
      const double lo = std::max(tlo[j], c.lo), hi = std::min(thi[j], c.hi);
      if (!(lo <= hi)) return false;
      if (hi - lo < 0.9 * (thi[j] - tlo[j])) shrunk = true;
      tlo[j] = lo;
      thi[j] = hi;
    }
    if (!shrunk) return true;  // val_ still encloses the (slightly) narrowed box
  }
}

}  // namespace detail
}  // namespace frep
