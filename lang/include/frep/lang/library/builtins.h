// HyperFun's operators and builtin functions as core expressions (semantics in
// docs/language.md; domain errors follow the core's conventions in frep/expressions/expr.h).
#pragma once

#include <string>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::lang {

// Tolerance of '=', '/=' and of truth values (hfp's EPS).
constexpr double kHfEps = 1e-6;

struct Builtin {
  const char* name;  // lower-case, as matched
  int arity;
  const char* summary;
  Expr (*lower)(const std::vector<Expr>& args);
};

const std::vector<Builtin>& builtins();
const Builtin* findBuiltin(const std::string& lowerName);

// Set operators: R-functions with alpha = 0.
Expr hfUnion(const Expr& a, const Expr& b);         // a + b + sqrt(a^2 + b^2)
Expr hfIntersection(const Expr& a, const Expr& b);  // a + b - sqrt(a^2 + b^2)
Expr hfDifference(const Expr& a, const Expr& b);    // a & -b
// '^': an integer constant exponent (within 1e-6 above an integer, as hfp) is a repeated
// product; anything else is pow (NaN for a negative base).
Expr hfPower(const Expr& base, const Expr& exponent);
// Nearest integer, ties up (hfp's HF_round): used by mod and by array indices.
Expr hfRound(const Expr& a);
double hfRound(double a);
// 1 when |v| >= 1e-6, else 0; comparison and logic results pass through unchanged.
Expr truth(const Expr& v);
Expr hfCompareEq(const Expr& a, const Expr& b);  // |a - b| < 1e-6
Expr hfCompareNe(const Expr& a, const Expr& b);  // |a - b| >= 1e-6

}  // namespace frep::lang
