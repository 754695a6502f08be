#include <gtest/gtest.h>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"

using namespace frep;

TEST(Expr, HashConsingSharesIdenticalSubexpressions) {
  Expr x = Expr::x(0), y = Expr::x(1);
  Expr a = sqrt(x * x + y * y);
  Expr b = sqrt(x * x + y * y);
  EXPECT_TRUE(a.same(b));
  EXPECT_TRUE((x + y).same(y + x));  // commutative canonical order
  EXPECT_EQ(nodeCount(a + b), nodeCount(a) + 1);
}

TEST(Expr, ConstantsFold) {
  Expr e = Expr(2.0) * 3.0 + sqrt(Expr(16.0));
  ASSERT_TRUE(e.isConst());
  EXPECT_EQ(e.constValue(), 10.0);
  EXPECT_TRUE((Expr::x(0) + 0.0).same(Expr::x(0)));
  EXPECT_TRUE((Expr::x(0) * 1.0).same(Expr::x(0)));
}

TEST(Tape, PointEvaluatesSphere) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr s = 1.0 - square(x) - square(y) - square(z);
  auto tape = Tape::compile(s);
  PointEvaluator pe;
  double p[3] = {0.5, 0.5, 0.0};
  EXPECT_DOUBLE_EQ(pe.eval(*tape, p), 0.5);
  BatchEvaluator<double> be;
  be.reserve(*tape);
  for (int k = 0; k < 10; ++k) {
    be.in(0)[k] = 0.1 * k;
    be.in(1)[k] = 0.0;
    be.in(2)[k] = 0.0;
  }
  const double* out = be.eval(*tape, 10);
  for (int k = 0; k < 10; ++k) EXPECT_DOUBLE_EQ(out[k], 1.0 - (0.1 * k) * (0.1 * k));
}

TEST(Expr, VeryDeepChainsAreBuiltEvaluatedAndFreedWithoutRecursion) {
  // 200000 nested operations: destruction must not recurse once per level.
  Expr e = Expr::x(0);
  for (int i = 0; i < 200000; ++i) e = sin(e) + 1.0;
  EXPECT_EQ(e.node().depth, 400000u);
  e = Expr();  // frees the whole chain
  EXPECT_TRUE(e.isConst(0.0));
}
