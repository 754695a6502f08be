// minMaxForm (see min_max_form.h): one memoised walk down the sign positions of the DAG.
#include "frep/expressions/min_max_form.h"

#include <cmath>
#include <unordered_map>

namespace frep {
namespace {

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
