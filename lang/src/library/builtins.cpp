#include "frep/lang/library/builtins.h"

#include <cmath>

#include "frep/primitives/ops.h"

namespace frep::lang {

// HyperFun's | and & are the core's a = 0 R-functions (one implementation for both layers).
Expr hfUnion(const Expr& a, const Expr& b) { return rUnion(a, b, 0.0); }
Expr hfIntersection(const Expr& a, const Expr& b) { return rIntersection(a, b, 0.0); }
Expr hfDifference(const Expr& a, const Expr& b) { return hfIntersection(a, -b); }

Expr hfPower(const Expr& base, const Expr& exponent) {
  if (exponent.isConst()) {
    double e = exponent.constValue();
    if (std::isfinite(e) && std::fabs(e) < 1e9 && e - std::floor(e) < kHfEps) {
      int n = static_cast<int>(hfRound(std::fabs(e)));
      return Expr::powi(base, e < 0 ? -n : n);
    }
  }
  return pow(base, exponent);
}

double hfRound(double a) {
  double c = std::ceil(a);
  return c - a > 0.5 ? c - 1.0 : c;
}

Expr hfRound(const Expr& a) {
  Expr c = ceil(a);
  return c - gt(c - a, 0.5);
}

Expr truth(const Expr& v) {
  if (v.isConst()) return Expr(std::fabs(v.constValue()) >= kHfEps ? 1.0 : 0.0);
  switch (v.op()) {
    case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
    case Op::And: case Op::Or: case Op::Not:
      return v;  // already 0 or 1
    default:
      return ge(abs(v), kHfEps);
  }
}

Expr hfCompareEq(const Expr& a, const Expr& b) { return lt(abs(a - b), kHfEps); }
Expr hfCompareNe(const Expr& a, const Expr& b) { return ge(abs(a - b), kHfEps); }

namespace {
using Args = std::vector<Expr>;
const std::vector<Builtin> kBuiltins = {
    {"abs", 1, "|a|", [](const Args& a) { return abs(a[0]); }},
    {"acos", 1, "arc cosine; argument clamped to [-1, 1]", [](const Args& a) { return acos(a[0]); }},
    {"asin", 1, "arc sine; argument clamped to [-1, 1]", [](const Args& a) { return asin(a[0]); }},
    {"atan", 1, "arc tangent", [](const Args& a) { return atan(a[0]); }},
    {"atan2", 2, "atan2(y, x): angle of (x, y)", [](const Args& a) { return atan2(a[0], a[1]); }},
    {"ceil", 1, "smallest integer >= a", [](const Args& a) { return ceil(a[0]); }},
    {"cos", 1, "cosine (radians)", [](const Args& a) { return cos(a[0]); }},
    {"cosh", 1, "hyperbolic cosine", [](const Args& a) { return cosh(a[0]); }},
    {"exp", 1, "e^a", [](const Args& a) { return exp(a[0]); }},
    {"floor", 1, "largest integer <= a", [](const Args& a) { return floor(a[0]); }},
    {"frac", 1, "a - int(a) (sign of a)", [](const Args& a) { return frac(a[0]); }},
    {"int", 1, "a truncated toward zero", [](const Args& a) { return trunc(a[0]); }},
    {"log", 1, "natural logarithm; argument floored at 1e-300", [](const Args& a) { return log(a[0]); }},
    {"logd", 1, "base-10 logarithm; argument floored at 1e-300", [](const Args& a) { return log10(a[0]); }},
    {"max", 2, "larger of two", [](const Args& a) { return max(a[0], a[1]); }},
    {"min", 2, "smaller of two", [](const Args& a) { return min(a[0], a[1]); }},
    {"mod", 2, "fmod(round(a), round(b)), rounding ties up; NaN when round(b) = 0",
     [](const Args& a) { return fmod(hfRound(a[0]), hfRound(a[1])); }},
    {"sign", 1, "-1, 0 or 1 (hfp always returns 1)", [](const Args& a) { return sign(a[0]); }},
    {"sin", 1, "sine (radians)", [](const Args& a) { return sin(a[0]); }},
    {"sinh", 1, "hyperbolic sine", [](const Args& a) { return sinh(a[0]); }},
    {"sqrt", 1, "square root; 0 for a negative argument", [](const Args& a) { return sqrt(a[0]); }},
    {"tan", 1, "tangent (radians)", [](const Args& a) { return tan(a[0]); }},
    {"tanh", 1, "hyperbolic tangent", [](const Args& a) { return tanh(a[0]); }},
};
}  // namespace

const std::vector<Builtin>& builtins() { return kBuiltins; }

const Builtin* findBuiltin(const std::string& lowerName) {
  for (const auto& b : kBuiltins)
    if (lowerName == b.name) return &b;
  return nullptr;
}

}  // namespace frep::lang
