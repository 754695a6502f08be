// The RAnd / ROr nodes: same values as the expanded formula, sound and tight intervals for any
// parameter a in (-1, 1], and derivatives that agree with central differences.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/primitives/ops.h"

using namespace frep;

namespace {
double expanded(bool disj, double f1, double f2, double a) {
  double root = std::sqrt(std::max(0.0, f1 * f1 + f2 * f2 - 2 * a * f1 * f2));
  return (f1 + f2 + (disj ? root : -root)) / (1 + a);
}
}  // namespace

TEST(RFunctionOp, ValuesMatchTheSurveyFormula) {
  EXPECT_EQ(applyOp(Op::ROr, 3, 4, 0, 0.0), 12.0);
  EXPECT_EQ(applyOp(Op::RAnd, 3, 4, 0, 0.0), 2.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-5, 5);
  for (double a : {0.0, 0.5, -0.5, -0.9, 0.99})
    for (int i = 0; i < 1000; ++i) {
      double f1 = u(rng), f2 = u(rng);
      EXPECT_NEAR(applyOp(Op::RAnd, f1, f2, 0, a), expanded(false, f1, f2, a), 1e-12);
      EXPECT_NEAR(applyOp(Op::ROr, f1, f2, 0, a), expanded(true, f1, f2, a), 1e-12);
    }
  // ops.h emits the node for constant a (and exact min/max for a = 1).
  Expr x = Expr::x(0), y = Expr::x(1);
  EXPECT_EQ(rIntersection(x, y, 0.3).op(), Op::RAnd);
  EXPECT_EQ(rUnion(x, y, 0.0).op(), Op::ROr);
  EXPECT_EQ(rUnion(x, y, 1.0).op(), Op::Max);
}

TEST(RFunctionOp, IntervalsAreSoundAndExactUpToRounding) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-10, 10);
  for (double a : {0.0, 0.5, -0.5, -0.9, 1.0})
    for (bool disj : {false, true})
      for (int i = 0; i < 2000; ++i) {
        double l1 = u(rng), l2 = u(rng);
        Interval A(l1, l1 + std::fabs(u(rng)) * (i % 3 == 0 ? 0.001 : 1.0));
        Interval B(l2, l2 + std::fabs(u(rng)));
        Op op = disj ? Op::ROr : Op::RAnd;
        Interval r = applyOp(op, A, B, Interval(), a);
        for (int k = 0; k < 16; ++k) {
          double f1 = A.lo + (A.hi - A.lo) * (k / 15.0), f2 = B.lo + (B.hi - B.lo) * ((k * 7 % 16) / 15.0);
          double v = applyOp(op, f1, f2, 0, a);
          ASSERT_TRUE(v >= r.lo && v <= r.hi) << v << " not in [" << r.lo << ", " << r.hi << "] a=" << a;
        }
        // Tight: the bounds are the values at the corners, widened only by rounding slack
        // (about sqrt(eps) of the operands where the radicand cancels, for a != 0).
        double exactLo = applyOp(op, A.lo, B.lo, 0, a), exactHi = applyOp(op, A.hi, B.hi, 0, a);
        double tol = (a == 0.0 ? 1e-12 : 1e-6) * 40 / (1 + std::min(a, 0.0));
        EXPECT_LE(exactLo - r.lo, tol);
        EXPECT_LE(r.hi - exactHi, tol);
      }
}

TEST(RFunctionOp, NestedRFunctionsKeepTightBoxBounds) {
  // Eight nested a = 0 intersections of slabs (hfBlock style): far from the solid the interval
  // must be entirely negative, which the expanded formula could not show.
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr f = (x + 1) * (1 - x);
  for (const Expr& c : {y, z, x + y, y - z, x - z, x + z, y + z}) f = rIntersection(f, (c + 1) * (1 - c), 0.0);
  auto tape = Tape::compile(f, 3);
  IntervalEvaluator ie;
  Interval far[3] = {{2.5, 2.6}, {2.5, 2.6}, {2.5, 2.6}};
  EXPECT_LT(ie.eval(*tape, far).hi, 0.0);
  Interval inside[3] = {{-0.05, 0.05}, {-0.05, 0.05}, {-0.05, 0.05}};
  EXPECT_GT(ie.eval(*tape, inside).lo, 0.0);
}

TEST(RFunctionOp, GradientMatchesCentralDifferencesAndSymbolicDerivative) {
  Expr x = Expr::x(0), y = Expr::x(1);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-2, 2);
  for (double a : {0.0, 0.5, -0.7}) {
    Expr f = rUnion(rIntersection(1 - x * x - y * y, x + 0.3, a), 0.2 - (x - 1) * (x - 1) - y * y, a);
    auto tape = Tape::compile(f, 2);
    auto dx = Tape::compile(derivative(f, 0), 2), dy = Tape::compile(derivative(f, 1), 2);
    GradientEvaluator ge;
    PointEvaluator pe;
    for (int i = 0; i < 200; ++i) {
      double p[2] = {u(rng), u(rng)}, g[2];
      ge.eval(*tape, p, g);
      const double h = 1e-6;
      double px[2] = {p[0] + h, p[1]}, mx[2] = {p[0] - h, p[1]}, py[2] = {p[0], p[1] + h}, my[2] = {p[0], p[1] - h};
      EXPECT_NEAR(g[0], (pe.eval(*tape, px) - pe.eval(*tape, mx)) / (2 * h), 1e-5);
      EXPECT_NEAR(g[1], (pe.eval(*tape, py) - pe.eval(*tape, my)) / (2 * h), 1e-5);
      EXPECT_NEAR(g[0], pe.eval(*dx, p), 1e-12);
      EXPECT_NEAR(g[1], pe.eval(*dy, p), 1e-12);
    }
  }
}

TEST(RFunctionOp, BatchEqualsPointBitForBit) {
  Expr x = Expr::x(0), y = Expr::x(1);
  Expr f = rIntersection(rUnion(x, y, 0.0), 1 - x * x - y * y, -0.4);
  auto tape = Tape::compile(f, 2);
  BatchEvaluator<double> be;
  be.reserve(*tape);
  PointEvaluator pe;
  for (int k = 0; k < 256; ++k) be.in(0)[k] = -1 + k / 128.0, be.in(1)[k] = std::sin(k * 0.1);
  const double* out = be.eval(*tape, 256);
  for (int k = 0; k < 256; ++k) {
    double p[2] = {-1 + k / 128.0, std::sin(k * 0.1)};
    ASSERT_EQ(out[k], pe.eval(*tape, p));
  }
}

TEST(DomainErrors, PointAndBatchCountEveryKind) {
  Expr x = Expr::x(0);
  // At x = -2: sqrt(-2), log(-2), asin(-2), 1/(x+2) = 1/0, (-2)^0.5, fmod(1, x+2) = fmod(1, 0).
  Expr f = sqrt(x) + log(x) + asin(x) + 1.0 / (x + 2.0) + pow(x, Expr(0.5)) + fmod(Expr(1.0), x + 2.0);
  auto tape = Tape::compile(f, 1);
  PointEvaluator pe;
  DomainCounts c;
  pe.countDomainErrors(&c);
  double p[1] = {-2.0};
  pe.eval(*tape, p);
  for (size_t k = 0; k < kDomainErrorKinds; ++k) EXPECT_EQ(c.n[k], 1u) << domainErrorName(DomainError(k));
  double q[1] = {0.5};
  pe.eval(*tape, q);  // no error at 0.5
  EXPECT_EQ(c.total(), kDomainErrorKinds);
  EXPECT_NE(c.describe().find("sqrt of a negative 1"), std::string::npos);

  BatchEvaluator<double> be;
  DomainCounts cb;
  be.countDomainErrors(&cb);
  be.reserve(*tape);
  for (int k = 0; k < 10; ++k) be.in(0)[k] = k < 3 ? -2.0 : 0.5;  // three lanes hit every kind
  be.eval(*tape, 10);
  for (size_t k = 0; k < kDomainErrorKinds; ++k) EXPECT_EQ(cb.n[k], 3u) << domainErrorName(DomainError(k));
}
