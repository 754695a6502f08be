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

namespace frep {
namespace detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

namespace {

// Outward-rounded interval ops (interval_fast.h: inlined on finite operands, this runs for every
// node of every box; anything else goes through applyOp).
inline Interval iadd(const Interval& a, const Interval& b) { return applyOpFast(Op::Add, a, b); }
inline Interval isub(const Interval& a, const Interval& b) { return applyOpFast(Op::Sub, a, b); }
inline Interval imul(const Interval& a, const Interval& b) { return applyOpFast(Op::Mul, a, b); }
inline Interval ineg(const Interval& a) { return Interval(-a.hi, -a.lo); }
inline bool isZeroIv(const Interval& a) { return a.lo == 0.0 && a.hi == 0.0; }
// Value of one op over intervals: inlined common cases, else applyOp.
inline Interval ival(Op op, const Interval& a, const Interval& b, const Interval& c, double imm, bool square) {
  if (square) {  // x * x: tighter as x^2 (bit for bit the same values at points)
    op = Op::PowI;
    imm = 2.0;
  }
  if (op == Op::Neg) return ineg(a);  // exact, whatever the bounds
  Interval r;
  if (fastOp(op, a, b, imm, r)) return r;
  return applyOp(op, a, b, c, imm);
}

// x := x intersected with y; false when empty.
inline bool meet(Interval& x, const Interval& y) {
  if (std::isnan(y.lo) || std::isnan(y.hi)) return true;  // no information
  x.lo = std::max(x.lo, y.lo);
  x.hi = std::min(x.hi, y.hi);
  return x.lo <= x.hi;
}
inline bool meetLo(Interval& x, double lo) { return meet(x, Interval(lo, kInf)); }
inline bool meetHi(Interval& x, double hi) { return meet(x, Interval(-kInf, hi)); }
// A lower bound of every a with RAnd_alpha(a, b) >= theta (b fixed; RAnd increases in a towards
// its supremum b): the root a* = theta (2b - theta (1 + alpha)) / (2 (b - theta)) of
// RAnd(a*, b) = theta, lowered by a margin far above its rounding error; -inf when unknown.
inline double rAndInverse(double theta, double b, double alpha) {
  if (!(std::fabs(theta) < kInf) || !(std::fabs(b) < kInf) || !(b > theta)) return -kInf;
  const double a = theta * (2.0 * b - theta * (1.0 + alpha)) / (2.0 * (b - theta));
  if (!std::isfinite(a)) return -kInf;
  // The closed form cancels as b -> theta: trust it only where the denominator is not tiny.
  if (!(b - theta > 1e-6 * (1.0 + std::fabs(b) + std::fabs(theta)))) return -kInf;
  return a - 1e-9 * (1.0 + std::fabs(a) + std::fabs(b) + std::fabs(theta));
}

// x := the part of x outside the open interval (-s, s) (as a hull), s >= 0.
inline bool excludeAround0(Interval& x, double s) {
  if (!(s > 0.0)) return true;
  if (x.lo > -s) return meetLo(x, s);
  if (x.hi < s) return meetHi(x, -s);
  return true;
}

}  // namespace

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

void TermForm::evalBox(const double* tlo, const double* thi) {
  const Interval everything = Interval::everything();
  const uint32_t p = p_;
  for (uint32_t k : dep_) {
    const Nd& q = nodes_[k];
    Interval* d = &der_[size_t(k) * p];
    if (q.op == Op::Var) {
      val_[k] = Interval(tlo[q.var - n_], thi[q.var - n_]);
      for (uint32_t j = 0; j < p; ++j) d[j] = Interval(j == q.var - n_ ? 1.0 : 0.0);
      continue;
    }
    const Interval A = val_[size_t(q.a)];
    const Interval B = q.b >= 0 ? val_[size_t(q.b)] : Interval();
    const Interval C = q.c >= 0 ? val_[size_t(q.c)] : Interval();
    val_[k] = ival(q.op, A, B, C, q.imm, q.square);
    const bool depA = nodes_[size_t(q.a)].dep, depB = q.b >= 0 && nodes_[size_t(q.b)].dep;
    const Interval* da = &der_[size_t(q.a) * p];
    const Interval* db = q.b >= 0 ? &der_[size_t(q.b) * p] : nullptr;
    const Interval zero(0.0);
    auto dA = [&](uint32_t j) { return depA ? da[j] : zero; };
    auto dB = [&](uint32_t j) { return depB ? db[j] : zero; };
    // p * d; an input derivative of exactly 0 contributes 0 whatever p is.
    auto term = [&](const Interval& pa, const Interval& dd) { return isZeroIv(dd) ? zero : imul(pa, dd); };
    auto unary = [&](const Interval& pa) {
      for (uint32_t j = 0; j < p; ++j) d[j] = term(pa, dA(j));
    };
    auto binary = [&](const Interval& pa, const Interval& pb) {
      for (uint32_t j = 0; j < p; ++j) d[j] = iadd(term(pa, dA(j)), term(pb, dB(j)));
    };
    auto all = [&](const Interval& v) {
      for (uint32_t j = 0; j < p; ++j) d[j] = v;
    };
    auto hullOf = [&](bool onlyA, bool onlyB) {
      for (uint32_t j = 0; j < p; ++j) {
        const Interval x = dA(j), y = dB(j);
        if (onlyA) d[j] = x;
        else if (onlyB) d[j] = y;
        else d[j] = Interval(std::min(x.lo, y.lo), std::max(x.hi, y.hi));
      }
    };
    switch (q.op) {
      case Op::Neg: for (uint32_t j = 0; j < p; ++j) d[j] = ineg(dA(j)); break;
      case Op::Copy: for (uint32_t j = 0; j < p; ++j) d[j] = dA(j); break;
      case Op::Add:
        for (uint32_t j = 0; j < p; ++j) d[j] = !depB ? dA(j) : !depA ? dB(j) : iadd(dA(j), dB(j));
        break;
      case Op::Sub:
        for (uint32_t j = 0; j < p; ++j) d[j] = !depB ? dA(j) : !depA ? ineg(dB(j)) : isub(dA(j), dB(j));
        break;
      case Op::Mul:
        if (q.square) unary(imul(Interval(2.0), A));
        else binary(B, A);
        break;
      case Op::Div: {  // d(a / b) = da / b - (a / b) db / b
        const Interval inv = applyOp(Op::Div, Interval(1.0), B);
        binary(inv, ineg(imul(val_[k], inv)));
        break;
      }
      case Op::PowI:
        unary(imul(Interval(q.imm), applyOp(Op::PowI, A, Interval(), Interval(), q.imm - 1.0)));
        break;
      case Op::Sqrt:  // unbounded slope where the argument may be 0
        if (A.lo > 0.0) unary(applyOp(Op::Div, Interval(0.5), val_[k]));
        else unary(everything);
        break;
      case Op::Abs: unary(A.lo > 0.0 ? Interval(1.0) : A.hi < 0.0 ? Interval(-1.0) : Interval(-1.0, 1.0)); break;
      case Op::Exp: unary(val_[k]); break;
      case Op::Log: unary(A.lo > kLogFloor ? applyOp(Op::Div, Interval(1.0), A) : everything); break;
      case Op::Sin: unary(applyOp(Op::Cos, A)); break;
      case Op::Cos: unary(ineg(applyOp(Op::Sin, A))); break;
      case Op::Atan: unary(applyOp(Op::Div, Interval(1.0), iadd(Interval(1.0), ival(Op::PowI, A, {}, {}, 2.0, false)))); break;
      case Op::Sinh: unary(applyOp(Op::Cosh, A)); break;
      case Op::Cosh: unary(applyOp(Op::Sinh, A)); break;
      case Op::Tanh: unary(isub(Interval(1.0), ival(Op::PowI, val_[k], {}, {}, 2.0, false))); break;
      case Op::Min: hullOf(A.hi <= B.lo, B.hi < A.lo); break;
      case Op::Max: hullOf(B.hi <= A.lo, B.lo > A.hi); break;
      case Op::Select:
        if (A.lo > 0.0 || A.hi < 0.0) {
          for (uint32_t j = 0; j < p; ++j) d[j] = dB(j);
        } else if (A.lo == 0.0 && A.hi == 0.0) {
          const bool depC = nodes_[size_t(q.c)].dep;
          for (uint32_t j = 0; j < p; ++j) d[j] = depC ? der_[size_t(q.c) * p + j] : zero;
        } else {
          all(everything);  // may jump
        }
        break;
      case Op::RAnd: case Op::ROr: {
        // Partials (1 -+ (f1 - a f2) / s) / (1 + a) and (1 -+ (f2 - a f1) / s) / (1 + a),
        // s = sqrt(f1^2 + f2^2 - 2 a f1 f2). Both lie in [0, 2 / (1 + a)] (monotone, and
        // |f1 - a f2| <= s for |a| <= 1), which also covers s = 0 (Clarke gradient there).
        const double al = q.imm;
        if (!(al > -1.0 && al <= 1.0)) {
          all(everything);
          break;
        }
        const Interval onePlus = iadd(Interval(1.0), Interval(al));
        const Interval range(0.0, applyOp(Op::Div, Interval(2.0), onePlus).hi);
        Interval p1 = range, p2 = range;
        const Interval s2 = isub(iadd(ival(Op::PowI, A, {}, {}, 2.0, false), ival(Op::PowI, B, {}, {}, 2.0, false)),
                                 imul(Interval(2.0 * al), imul(A, B)));
        if (s2.lo > 0.0 && finiteIv(s2)) {
          const Interval s = ival(Op::Sqrt, s2, {}, {}, 0.0, false);
          Interval q1 = applyOp(Op::Div, isub(A, imul(Interval(al), B)), s);
          Interval q2 = applyOp(Op::Div, isub(B, imul(Interval(al), A)), s);
          const Interval sg(q.op == Op::RAnd ? -1.0 : 1.0);
          const Interval t1 = applyOp(Op::Div, iadd(Interval(1.0), imul(sg, q1)), onePlus);
          const Interval t2 = applyOp(Op::Div, iadd(Interval(1.0), imul(sg, q2)), onePlus);
          p1 = Interval(std::max(t1.lo, 0.0), std::min(t1.hi, range.hi));
          p2 = Interval(std::max(t2.lo, 0.0), std::min(t2.hi, range.hi));
          if (!(p1.lo <= p1.hi)) p1 = range;
          if (!(p2.lo <= p2.hi)) p2 = range;
        }
        binary(p1, p2);
        break;
      }
      case Op::Floor: case Op::Ceil: case Op::Trunc: case Op::Not: case Op::Lt: case Op::Le:
      case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: case Op::And: case Op::Or:
        // piecewise constant: slope 0 where constant over the box, else it may jump
        all(val_[k].lo == val_[k].hi ? zero : everything);
        break;
      default:
        all(everything);
        break;
    }
    for (uint32_t j = 0; j < p; ++j)
      if (std::isnan(d[j].lo) || std::isnan(d[j].hi)) d[j] = everything;
  }
}

void TermForm::evalCentre(const double* c) {
  for (uint32_t k : dep_) {
    const Nd& q = nodes_[k];
    if (q.op == Op::Var) {
      valC_[k] = Interval(c[q.var - n_]);
      continue;
    }
    valC_[k] = ival(q.op, valC_[size_t(q.a)], q.b >= 0 ? valC_[size_t(q.b)] : Interval(),
                             q.c >= 0 ? valC_[size_t(q.c)] : Interval(), q.imm, q.square);
  }
}

double TermForm::upper(const double* tlo, const double* thi) {
  const uint32_t p = p_;
  evalBox(tlo, thi);
  cbuf_.resize(p);
  Dv_.resize(p);
  for (uint32_t j = 0; j < p; ++j) {
    cbuf_[j] = 0.5 * (tlo[j] + thi[j]);
    Dv_[j] = isub(Interval(tlo[j], thi[j]), Interval(cbuf_[j]));
  }
  evalCentre(cbuf_.data());
  const size_t K = terms_.size();
  Gl_.assign(K * p, 0.0);
  Gh_.assign(K * p, 0.0);
  vv_.assign(K, kInf);
  double best = kInf, slack = 0.0;
  for (size_t i = 0; i < K; ++i) {
    const size_t node = size_t(terms_[i]);
    const Interval vc = valC_[node];
    double ub = val_[node].hi;
    if (std::isnan(ub)) ub = kInf;
    if (!finiteIv(vc)) {
      best = std::min(best, ub);
      continue;
    }
    Interval acc = vc;
    bool finiteG = true;
    for (uint32_t j = 0; j < p; ++j) {
      const Interval g = nodes_[node].dep ? der_[node * p + j] : Interval(0.0);
      if (!finiteIv(g)) finiteG = false;
      Gl_[i * p + j] = g.lo;
      Gh_[i * p + j] = g.hi;
      acc = iadd(acc, imul(g, Dv_[j]));
    }
    if (finiteG) {
      ub = std::min(ub, acc.hi);
      vv_[i] = vc.hi;
      // Rounding of the computed body near c (the centred form bounds the exact terms): the
      // width of the centre's enclosure, which accumulates one ulp per operation.
      slack = std::max(slack, vc.hi - vc.lo);
    }
    best = std::min(best, ub);
  }
  // Weighted combination of the terms that may be active (centre value below the bound).
  csel_.clear();
  for (size_t i = 0; i < K; ++i)
    if (vv_[i] < best) csel_.push_back(uint32_t(i));
  if (csel_.size() >= 2 && p <= 16) {
    if (csel_.size() > 5) {
      std::partial_sort(csel_.begin(), csel_.begin() + 5, csel_.end(), [&](uint32_t a, uint32_t b) { return vv_[a] < vv_[b]; });
      csel_.resize(5);
    }
    const size_t S = csel_.size();
    clam_.assign(S, 0.0);
    size_t i0 = 0;
    for (size_t a = 1; a < S; ++a)
      if (vv_[csel_[a]] < vv_[csel_[i0]]) i0 = a;
    clam_[i0] = 1.0;
    // Surrogate phi(lambda) = sum lambda_i v_i + sum_j r_j max(H_j, -L_j), with H, L the
    // weighted sums of the gradient bounds: convex and piecewise linear, so exact line searches
    // moving weight between two terms only need its breakpoints.
    H_.assign(p, 0.0);
    L_.assign(p, 0.0);
    for (uint32_t j = 0; j < p; ++j) {
      H_[j] = Gh_[csel_[i0] * p + j];
      L_[j] = Gl_[csel_[i0] * p + j];
    }
    double V = vv_[csel_[i0]];
    double dH[16], dL[16];
    auto phiAt = [&](double s, double dV) {
      double f = V + s * dV;
      for (uint32_t j = 0; j < p; ++j) f += Dv_[j].hi * std::max(H_[j] + s * dH[j], -(L_[j] + s * dL[j]));
      return f;
    };
    for (int sweep = 0; sweep < 2; ++sweep) {
      for (size_t a = 0; a < S; ++a) {
        for (size_t b = 0; b < S; ++b) {
          if (a == b || clam_[a] <= 0.0) continue;
          const uint32_t ia = csel_[a], ib = csel_[b];
          for (uint32_t j = 0; j < p; ++j) {
            dH[j] = Gh_[ib * p + j] - Gh_[ia * p + j];
            dL[j] = Gl_[ib * p + j] - Gl_[ia * p + j];
          }
          const double dV = vv_[ib] - vv_[ia];
          double bestS = 0.0, bestF = phiAt(0.0, dV);
          auto tryS = [&](double s) {
            if (!(s > 0.0) || s > clam_[a]) return;
            const double f = phiAt(s, dV);
            if (f < bestF) {
              bestF = f;
              bestS = s;
            }
          };
          tryS(clam_[a]);
          for (uint32_t j = 0; j < p; ++j) {
            const double dm = dH[j] + dL[j];
            if (dm != 0.0) tryS(-(H_[j] + L_[j]) / dm);
          }
          if (bestS > 0.0) {
            clam_[a] = std::max(0.0, clam_[a] - bestS);
            clam_[b] += bestS;
            for (uint32_t j = 0; j < p; ++j) {
              H_[j] += bestS * dH[j];
              L_[j] += bestS * dL[j];
            }
            V += bestS * dV;
          }
        }
      }
    }
    // Rigorous value at these weights.
    Interval num(0.0), den(0.0);
    for (size_t a = 0; a < S; ++a) {
      if (clam_[a] <= 0.0) continue;
      num = iadd(num, imul(Interval(clam_[a]), valC_[size_t(terms_[csel_[a]])]));
      den = iadd(den, Interval(clam_[a]));
    }
    for (uint32_t j = 0; j < p; ++j) {
      Interval g(0.0);
      for (size_t a = 0; a < S; ++a)
        if (clam_[a] > 0.0) g = iadd(g, imul(Interval(clam_[a]), Interval(Gl_[csel_[a] * p + j], Gh_[csel_[a] * p + j])));
      num = iadd(num, imul(g, Dv_[j]));
    }
    if (den.lo > 0.0 && finiteIv(num)) {
      const Interval u = applyOp(Op::Div, num, den);
      if (u.hi < best) best = u.hi;
    }
  }
  return best + slack;
}

namespace {
// Values of the common ops as applyOp computes them (same bits), without its call.
inline double pointValue(Op op, double a, double b, double c, double imm) {
  switch (op) {
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Neg: return -a;
    case Op::Min: return b < a ? b : a;
    case Op::Max: return b > a ? b : a;
    default: return applyOp(op, a, b, c, imm);
  }
}
}  // namespace

// P: the number of parameters when known at compile time (the loops over them unroll), else 0.
// The gradient of step q from its operands' gradients (pd_), a = its first operand's value,
// b = its second's, v = its own.
template <uint32_t P>
inline void TermForm::stepGrad(const Step& q, double a, double b, double v) {
  const uint32_t p = P ? P : p_;
  double* pd = pd_.data();
  double* d = pd + size_t(q.k) * p;
  const bool depA = q.depA, depB = q.depB;
  const double* da = pd + size_t(q.a) * p;
  const double* db = pd + size_t(q.b) * p;
  double pa = 0.0, pb = 0.0;
  const double* pass = nullptr;
  switch (q.op) {
    case Op::Neg: pa = -1.0; break;
    case Op::Copy: pa = 1.0; break;
    case Op::Add: pa = 1.0; pb = 1.0; break;
    case Op::Sub: pa = 1.0; pb = -1.0; break;
    case Op::Mul: pa = b; pb = a; break;
    case Op::Div: pa = 1.0 / b; pb = -v / b; break;
    case Op::PowI: pa = q.imm * applyOp(Op::PowI, a, 0.0, 0.0, q.imm - 1.0); break;
    case Op::Sqrt: pa = a > 0.0 ? 0.5 / v : 0.0; break;
    case Op::Abs: pa = a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : 0.0; break;
    case Op::Exp: pa = v; break;
    case Op::Log: pa = a > kLogFloor ? 1.0 / a : 0.0; break;
    case Op::Sin: pa = ownCos(a); break;
    case Op::Cos: pa = -ownSin(a); break;
    case Op::Atan: pa = 1.0 / (1.0 + a * a); break;
    case Op::Tanh: pa = 1.0 - v * v; break;
    case Op::Min: if (b < a ? depB : depA) pass = b < a ? db : da; break;
    case Op::Max: if (b > a ? depB : depA) pass = b > a ? db : da; break;
    case Op::RAnd: case Op::ROr: rFunctionPartials(q.op == Op::ROr, a, b, q.imm, pa, pb); break;
    default: break;
  }
  if (pass) {
    for (uint32_t j = 0; j < p; ++j) d[j] = pass[j];
  } else {
    const bool useA = depA && pa != 0.0, useB = depB && pb != 0.0;
    for (uint32_t j = 0; j < p; ++j) {
      double s = 0.0;
      if (useA) s += pa * da[j];
      if (useB) s += pb * db[j];
      d[j] = std::isfinite(s) ? s : 0.0;
    }
  }
}

template <uint32_t P>
double TermForm::pointGradImpl(const double* t) {
  const uint32_t p = P ? P : p_;
  double* pv = pv_.data();
  const double* pd = pd_.data();
  for (const Step& q : steps_) {
    if (q.op == Op::Var) {
      pv[q.k] = t[q.var];
      continue;  // constant gradient (build)
    }
    const double a = pv[q.a], b = pv[q.b];
    const double v = pointValue(q.op, a, b, pv[q.c], q.imm);
    pv[q.k] = v;
    if (!q.constGrad) stepGrad<P>(q, a, b, v);
  }
  const size_t K = terms_.size();
  tv_.resize(K);
  tg_.resize(K * p);
  double f = kInf;
  for (size_t i = 0; i < K; ++i) {
    const size_t node = size_t(terms_[i]);
    tv_[i] = pv[node];
    const bool dep = nodes_[node].dep;
    for (uint32_t j = 0; j < p; ++j) tg_[i * p + j] = dep ? pd[node * p + j] : 0.0;
    f = std::min(f, tv_[i]);
  }
  return f;
}

double TermForm::pointMin(const double* t) {
  double* pv = pv_.data();
  for (const Step& q : steps_) pv[q.k] = q.op == Op::Var ? t[q.var] : pointValue(q.op, pv[q.a], pv[q.b], pv[q.c], q.imm);
  double f = kInf;
  for (int32_t node : terms_) f = std::min(f, pv[size_t(node)]);
  return f;
}

double TermForm::pointGrad(const double* t) {
  switch (p_) {
    case 1: return pointGradImpl<1>(t);
    case 2: return pointGradImpl<2>(t);
    case 3: return pointGradImpl<3>(t);
    default: return pointGradImpl<0>(t);
  }
}

uint32_t TermForm::ascend(double* t, const double* plo, const double* phi, double tol, double stopAbove) {
  switch (p_) {
    case 1: return ascendImpl<1>(t, plo, phi, tol, stopAbove);
    case 2: return ascendImpl<2>(t, plo, phi, tol, stopAbove);
    case 3: return ascendImpl<3>(t, plo, phi, tol, stopAbove);
    default: return ascendImpl<0>(t, plo, phi, tol, stopAbove);
  }
}

template <uint32_t P>
uint32_t TermForm::ascendImpl(double* t, const double* plo, const double* phi, double tol, double stopAbove) {
  lastF_ = -kInf;
  const size_t K = terms_.size();
  const uint32_t p = P ? P : p_;
  uint32_t calls = 1;
  double F = pointGradImpl<P>(t);
  lastF_ = F;
  if (!std::isfinite(F) || F > stopAbove) return calls;
  std::vector<double>& av = av_;
  std::vector<double>& ag = ag_;
  av.assign(tv_.begin(), tv_.end());
  ag.assign(tg_.begin(), tg_.end());
  double width = 0.0, gmax = 0.0;
  for (uint32_t k = 0; k < p; ++k) width = std::max(width, phi[k] - plo[k]);
  for (size_t i = 0; i < K; ++i) {
    double g2 = 0.0;
    for (uint32_t j = 0; j < p; ++j) g2 += ag[i * p + j] * ag[i * p + j];
    if (std::isfinite(g2)) gmax = std::max(gmax, std::sqrt(g2));
  }
  if (!(gmax > 0.0) || !(width > 0.0)) return calls;
  double mu = gmax / (0.125 * width);
  std::vector<double>& lam = lam_;
  std::vector<double>& w = w_;
  std::vector<double>& t1 = t1_;
  std::vector<uint32_t>& S = sel_;
  w.resize(p);
  t1.resize(p);
  for (int it = 0; it < 8 && calls < 8; ++it) {
    // Terms that can become active within the step scale.
    const double reach = 2.0 * gmax * gmax / mu;
    S.clear();
    size_t i0 = 0;
    for (size_t i = 0; i < K; ++i) {
      if (av[i] < av[i0]) i0 = i;
      if (av[i] <= F + reach && std::isfinite(av[i])) S.push_back(uint32_t(i));
    }
    lam.assign(K, 0.0);
    lam[i0] = 1.0;
    for (uint32_t j = 0; j < p; ++j) w[j] = ag[i0 * p + j];
    // Per pair (a, b) of S: the gradient difference g_b - g_a and its square norm, computed on
    // first use and kept for the later sweeps.
    const size_t ns = S.size();
    pairDone_.assign(ns * ns, 0);
    pairD_.resize(ns * ns * p);
    pairDD_.resize(ns * ns);
    for (int sweep = 0; sweep < 6 && ns > 1; ++sweep) {
      bool moved = false;  // a sweep that moves nothing leaves the same state for the next
      for (size_t ia = 0; ia < ns; ++ia) {
        const uint32_t a = S[ia];
        if (lam[a] <= 0.0) continue;  // (lam[a] only decreases while a gives weight away)
        for (size_t ib = 0; ib < ns; ++ib) {
          const uint32_t b = S[ib];
          if (a == b || lam[a] <= 0.0) continue;
          const size_t pair = ia * ns + ib;
          double* D = &pairD_[pair * p];
          if (!pairDone_[pair]) {
            double dd = 0.0;
            for (uint32_t j = 0; j < p; ++j) {
              D[j] = ag[b * p + j] - ag[a * p + j];
              dd += D[j] * D[j];
            }
            pairDD_[pair] = dd;
            pairDone_[pair] = 1;
          }
          double wd = 0.0;
          for (uint32_t j = 0; j < p; ++j) wd += w[j] * D[j];
          const double dd = pairDD_[pair];
          double sMove;
          if (dd > 0.0) sMove = -(mu * (av[b] - av[a]) + wd) / dd;
          else sMove = av[b] < av[a] ? lam[a] : 0.0;
          sMove = std::min(lam[a], sMove);
          if (!(sMove > 0.0)) continue;
          lam[a] -= sMove;
          lam[b] += sMove;
          for (uint32_t j = 0; j < p; ++j) w[j] += sMove * D[j];
          moved = true;
        }
      }
      if (!moved) break;
    }
    for (uint32_t j = 0; j < p; ++j) t1[j] = std::min(phi[j], std::max(plo[j], t[j] + w[j] / mu));
    double pred = kInf;
    for (size_t i = 0; i < K; ++i) {
      double v = av[i];
      for (uint32_t j = 0; j < p; ++j) v += ag[i * p + j] * (t1[j] - t[j]);
      pred = std::min(pred, v);
    }
    pred -= F;
    if (!(pred > 1e-3 * tol)) break;
    ++calls;
    const double F1 = pointGradImpl<P>(t1.data());
    if (F1 - F >= 0.1 * pred) {
      // mu only grows: halving it after well-predicted steps (longer steps) took fewer steps
      // but more work per step in the dual (more terms within reach), 3% more in all.
      const bool small = F1 - F < 1e-2 * tol;
      std::copy(t1.begin(), t1.end(), t);
      F = lastF_ = F1;
      av.assign(tv_.begin(), tv_.end());
      ag.assign(tg_.begin(), tg_.end());
      if (small || F > stopAbove) break;
    } else {
      mu *= 4.0;
    }
  }
  return calls;
}

}  // namespace detail
}  // namespace frep
