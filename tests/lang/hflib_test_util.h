// Helpers for the hf* library tests: build call arguments, lower a call through the registry,
// and evaluate the resulting expression at a point (compiled tape, cross-checked against
// constant folding of the same DAG).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/lang/library/library.h"
#include "frep/expressions/tape.h"

namespace hftest {

using frep::Expr;
using frep::lang::Arg;

constexpr double kPi = 3.14159265358979323846;

inline std::vector<Expr> xyz() { return {Expr::x(0), Expr::x(1), Expr::x(2)}; }

inline std::vector<Expr> vals(std::initializer_list<double> v) {
  return std::vector<Expr>(v.begin(), v.end());
}

inline Arg arr(std::vector<Expr>& v, const std::string& name = "") {
  Arg a;
  a.isArray = true;
  a.array = &v;
  a.name = name;
  return a;
}

inline Arg sc(const Expr& e) {
  Arg a;
  a.value = e;
  return a;
}

inline Expr call(const std::string& name, std::vector<Arg> args) {
  const frep::lang::LibraryFunction* f = frep::lang::findLibraryFunction(name);
  if (!f) throw std::runtime_error("not registered: " + name);
  if (f->signature != "*" && f->signature.size() != args.size())
    throw std::runtime_error(name + ": test passes a wrong number of arguments");
  return f->lower(args);
}

// Value of e at (x, y, z): through a compiled tape, checked against constant folding.
inline double at(const Expr& e, double x = 0, double y = 0, double z = 0) {
  Expr folded = frep::remap(e, {Expr(x), Expr(y), Expr(z)});
  EXPECT_TRUE(folded.isConst()) << frep::toString(folded);
  auto tape = frep::Tape::compile(e, 3);
  frep::PointEvaluator ev;
  double p[3] = {x, y, z};
  double v = ev.eval(*tape, p);
  double f = folded.constValue();
  EXPECT_NEAR(v, f, 1e-12 * std::max(1.0, std::fabs(f)));
  return v;
}

// 1e-9 relative (absolute near 0).
inline void expectClose(double actual, double expected) {
  EXPECT_NEAR(actual, expected, 1e-9 * std::max(1.0, std::fabs(expected)));
}

// Runs the call and returns the LibraryError message and argument index.
inline std::pair<std::string, int> errorOf(const std::string& name, std::vector<Arg> args) {
  try {
    call(name, std::move(args));
  } catch (const frep::lang::LibraryError& e) {
    return {e.what(), e.argIndex};
  }
  return {"<no error>", -2};
}

}  // namespace hftest
