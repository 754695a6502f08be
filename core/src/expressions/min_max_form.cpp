// minMaxForm (see min_max_form.h): one memoised walk down the sign positions of the DAG.
#include "frep/expressions/min_max_form.h"

#include <cmath>
#include <map>
#include <optional>
#include <unordered_map>

namespace frep {
namespace {

// An affine form sum_i c_i x[i] + c0, when e is one (built from vars, constants, +, -, negation
// and products/quotients by constants).
struct Affine {
  std::map<uint32_t, double> coef;
  double c0 = 0.0;
};

std::optional<Affine> affine(const Expr& e, int depth = 0) {
  if (depth > 64) return std::nullopt;
  auto combine = [](Affine a, const Affine& b, double sb) {
    for (auto& [v, c] : b.coef) a.coef[v] += sb * c;
    a.c0 += sb * b.c0;
    return a;
  };
  auto scaled = [](Affine a, double k) {
    for (auto& kv : a.coef) kv.second *= k;
    a.c0 *= k;
    return a;
  };
  switch (e.op()) {
    case Op::Const: return Affine{{}, e.constValue()};
    case Op::Var: return Affine{{{e.node().index, 1.0}}, 0.0};
    case Op::Neg: {
      auto a = affine(e.arg(0), depth + 1);
      return a ? std::optional<Affine>(scaled(*a, -1.0)) : std::nullopt;
    }
    case Op::Add: case Op::Sub: {
      auto a = affine(e.arg(0), depth + 1), b = affine(e.arg(1), depth + 1);
      if (!a || !b) return std::nullopt;
      return combine(*a, *b, e.op() == Op::Add ? 1.0 : -1.0);
    }
    case Op::Mul: {
      if (e.arg(0).isConst()) {
        auto b = affine(e.arg(1), depth + 1);
        return b ? std::optional<Affine>(scaled(*b, e.arg(0).constValue())) : std::nullopt;
      }
      if (e.arg(1).isConst()) {
        auto a = affine(e.arg(0), depth + 1);
        return a ? std::optional<Affine>(scaled(*a, e.arg(1).constValue())) : std::nullopt;
      }
      return std::nullopt;
    }
    default: return std::nullopt;
  }
}

// p * q with p + q a constant >= 0 (HyperFun's slabs (x - v)(v + d - x), d >= 0): p and q
// cannot both be negative, so the product has the sign of min(p, q).
bool complementaryFactors(const Expr& p, const Expr& q) {
  auto a = affine(p), b = affine(q);
  if (!a || !b || a->coef.empty()) return false;
  for (auto& [v, c] : a->coef) {
    auto it = b->coef.find(v);
    if (it == b->coef.end() || c + it->second != 0.0) return false;
  }
  for (auto& [v, c] : b->coef)
    if (c != 0.0 && !a->coef.count(v)) return false;
  return a->c0 + b->c0 >= 0.0;
}

class MinMaxRewriter {
 public:
  Expr operator()(const Expr& e) {
    auto it = memo_.find(e.ptr().get());
    if (it != memo_.end()) return it->second;
    Expr r = rewrite(e);
    memo_.emplace(e.ptr().get(), r);
    return r;
  }
  bool changed = false;

 private:
  static bool positiveConst(const Expr& e) { return e.isConst() && e.constValue() > 0.0 && std::isfinite(e.constValue()); }

  Expr rewrite(const Expr& e) {
    switch (e.op()) {
      case Op::RAnd:
        changed = true;
        return min((*this)(e.arg(0)), (*this)(e.arg(1)));
      case Op::ROr:
        changed = true;
        return max((*this)(e.arg(0)), (*this)(e.arg(1)));
      case Op::Min:
      case Op::Max:
        return Expr::make(e.op(), (*this)(e.arg(0)), (*this)(e.arg(1)));
      case Op::Neg:
        return -(*this)(e.arg(0));
      case Op::Mul:
        if (positiveConst(e.arg(0))) return e.arg(0) * (*this)(e.arg(1));
        if (positiveConst(e.arg(1))) return (*this)(e.arg(0)) * e.arg(1);
        if (complementaryFactors(e.arg(0), e.arg(1))) {
          changed = true;
          return min(e.arg(0), e.arg(1));
        }
        return e;
      case Op::Div:
        if (positiveConst(e.arg(1))) return (*this)(e.arg(0)) / e.arg(1);
        return e;
      case Op::Select:
        return select(e.arg(0), (*this)(e.arg(1)), (*this)(e.arg(2)));
      default:
        return e;  // uses values (or is a leaf): nothing beneath is in sign position
    }
  }

  std::unordered_map<const Node*, Expr> memo_;
};

}  // namespace

Expr minMaxForm(const Expr& e) {
  MinMaxRewriter r;
  return r(e);
}

bool hasSignPositionRFunction(const Expr& e) {
  MinMaxRewriter r;
  r(e);
  return r.changed;
}

}  // namespace frep
