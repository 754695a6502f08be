// Helpers for the language tests: compile a model and evaluate it at a point.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/lang/hyperfun.h"
#include "frep/expressions/tape.h"

namespace frep::lang::testing {

inline std::string allDiagnostics(const CompileResult& r) {
  std::string s;
  for (const auto& d : r.diagnostics) s += d.format() + "\n";
  return s;
}

// Compiles src and expects success.
inline Model compileOk(const std::string& src, const CompileOptions& opt = {}) {
  CompileResult r = compile(src, "test.hf", opt);
  EXPECT_TRUE(r.ok) << allDiagnostics(r);
  return r.model;
}

// Evaluates a compiled model at x with parameters a (through the tape, as the farm does).
inline double evalModel(const Model& m, std::vector<double> x, const std::vector<double>& a = {}) {
  std::vector<Expr> params;
  for (double v : a) params.push_back(Expr(v));
  while (params.size() < static_cast<size_t>(m.aSize)) params.push_back(Expr(0.0));
  Expr f = bindParams(m.field, params);
  x.resize(std::max<size_t>(x.size(), static_cast<size_t>(m.xSize)), 0.0);
  auto tape = Tape::compile(f, static_cast<uint32_t>(x.size()));
  PointEvaluator ev;
  return ev.eval(*tape, x.data());
}

// Value of `expr` in a 3D model with x = (x1, x2, x3).
inline double valueOf(const std::string& expr, std::vector<double> x = {0, 0, 0}) {
  Model m = compileOk("my_model(x[3], a[1]) { my_model = " + expr + "; }");
  return evalModel(m, x);
}

// Whether f still holds an extremum node (a search), i.e. no exact path took the operation.
inline bool hasExtremum(const Expr& f) {
  bool found = false;
  forEachNode(f, [&](const Node& n) { found = found || n.op == Op::Extremum; });
  return found;
}

// The unit cube [0, 1]^3 as six flat Bezier patches: a closed mesh operand ("cube").
inline const std::string kBezierCube =
    "cube(x[3], a[1]) {\n"
    "  array c[72];\n"
    "  c = [0,0,0, 0,1,0, 1,0,0, 1,1,0,   0,0,1, 1,0,1, 0,1,1, 1,1,1,\n"
    "       0,0,0, 1,0,0, 0,0,1, 1,0,1,   0,1,0, 0,1,1, 1,1,0, 1,1,1,\n"
    "       0,0,0, 0,0,1, 0,1,0, 0,1,1,   1,0,0, 1,1,0, 1,0,1, 1,1,1];\n"
    "  cube = frBezierSurface(x, c, 1, 1);\n"
    "}\n";

// Expects relative agreement to 1e-9 (absolute near zero).
#define EXPECT_CLOSE(actual, expected)                                                  \
  do {                                                                                  \
    double a_ = (actual), e_ = (expected);                                              \
    EXPECT_NEAR(a_, e_, 1e-9 * std::max(1.0, std::fabs(e_))) << "expected " << e_;      \
  } while (0)

}  // namespace frep::lang::testing
