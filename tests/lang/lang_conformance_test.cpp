// Operators, precedence and builtins against HyperFun's semantics, value by value.
#include <cmath>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

double uni(double a, double b) { return a + b + std::sqrt(a * a + b * b); }
double inter(double a, double b) { return a + b - std::sqrt(a * a + b * b); }

TEST(LangConformance, SetOperatorCheckValues) {
  EXPECT_CLOSE(valueOf("3|4"), 12.0);
  EXPECT_CLOSE(valueOf("3&4"), 2.0);
  EXPECT_CLOSE(valueOf("3\\4"), -6.0);
  EXPECT_CLOSE(valueOf("3@4"), 2.0);  // computes like &
  EXPECT_CLOSE(valueOf("~3"), -3.0);
  EXPECT_NEAR(valueOf("1 | 2*3"), 13.082763, 1e-6);
  EXPECT_CLOSE(valueOf("1 | 2*3"), 7.0 + std::sqrt(37.0));
}

TEST(LangConformance, SetOperatorsOnCoordinates) {
  std::vector<double> p = {0.3, -1.7, 2.5};
  EXPECT_CLOSE(valueOf("x[1] | x[2]", p), uni(0.3, -1.7));
  EXPECT_CLOSE(valueOf("x[1] & x[3]", p), inter(0.3, 2.5));
  EXPECT_CLOSE(valueOf("x[2] \\ x[3]", p), inter(-1.7, -2.5));
  EXPECT_CLOSE(valueOf("x[2] @ x[1]", p), inter(-1.7, 0.3));
}

TEST(LangConformance, ArithmeticOperators) {
  std::vector<double> p = {1.5, -2.25, 4.0};
  EXPECT_CLOSE(valueOf("x[1] + x[2]", p), 1.5 - 2.25);
  EXPECT_CLOSE(valueOf("x[1] - x[2]", p), 1.5 + 2.25);
  EXPECT_CLOSE(valueOf("x[1] * x[2]", p), 1.5 * -2.25);
  EXPECT_CLOSE(valueOf("x[1] / x[2]", p), 1.5 / -2.25);
  EXPECT_CLOSE(valueOf("x[3] ^ 0.5", p), 2.0);
  EXPECT_CLOSE(valueOf("x[2] ^ 3", p), -2.25 * -2.25 * -2.25);
  EXPECT_CLOSE(valueOf("x[2] ^ -2", p), 1.0 / (2.25 * 2.25));
  EXPECT_CLOSE(valueOf("x[1] ^ x[3]", p), std::pow(1.5, 4.0));
  EXPECT_CLOSE(valueOf("-x[1]", p), -1.5);
  EXPECT_CLOSE(valueOf("+x[1]", p), 1.5);
}

TEST(LangConformance, Precedence) {
  EXPECT_CLOSE(valueOf("-2^2"), 4.0);      // unary binds tighter than ^
  EXPECT_CLOSE(valueOf("2^3^2"), 64.0);    // ^ is left associative
  EXPECT_CLOSE(valueOf("2+3*4"), 14.0);
  EXPECT_CLOSE(valueOf("2*3^2"), 18.0);
  EXPECT_CLOSE(valueOf("10-4-3"), 3.0);    // left associative
  EXPECT_CLOSE(valueOf("8/4/2"), 1.0);
  EXPECT_CLOSE(valueOf("1 - 2 | 3"), uni(-1, 3));  // + - | one level, left to right
  EXPECT_CLOSE(valueOf("1 | 2 - 3"), uni(1, 2) - 3);
  EXPECT_CLOSE(valueOf("1 & 2 + 3"), inter(1, 2) + 3);
  EXPECT_CLOSE(valueOf("(1 + 2) * 3"), 9.0);
}

TEST(LangConformance, DoubleMinusIsAComment) {
  // hfp: "a--1" is "a" followed by a comment.
  Model m = compileOk("my_model(x[1], a[1]) { my_model = 5--1;\n; }");
  EXPECT_CLOSE(evalModel(m, {0}), 5.0);
  EXPECT_CLOSE(valueOf("- -2"), 2.0);
}

TEST(LangConformance, Comparisons) {
  EXPECT_CLOSE(valueOf("(1 = 1.0000005)"), 1.0);  // within 1e-6
  EXPECT_CLOSE(valueOf("(1 = 1.000002)"), 0.0);
  EXPECT_CLOSE(valueOf("(1 /= 1.0000005)"), 0.0);
  EXPECT_CLOSE(valueOf("(1 /= 1.000002)"), 1.0);
  EXPECT_CLOSE(valueOf("(1 < 2)"), 1.0);
  EXPECT_CLOSE(valueOf("(2 < 2)"), 0.0);
  EXPECT_CLOSE(valueOf("(2 <= 2)"), 1.0);
  EXPECT_CLOSE(valueOf("(3 > 2)"), 1.0);
  EXPECT_CLOSE(valueOf("(2 >= 3)"), 0.0);
  EXPECT_CLOSE(valueOf("(2 <= 7 < 5.5)"), 1.0);  // chains: (2<=7) < 5.5
  EXPECT_CLOSE(valueOf("(1 and 0.0000001)"), 0.0);  // truth needs |v| >= 1e-6
  EXPECT_CLOSE(valueOf("(1 and 2)"), 1.0);
  EXPECT_CLOSE(valueOf("(0 or 0.5)"), 1.0);
  EXPECT_CLOSE(valueOf("(0 or 0)"), 0.0);
  EXPECT_CLOSE(valueOf("(not 0)"), 1.0);
  EXPECT_CLOSE(valueOf("(not 3)"), 0.0);
  EXPECT_CLOSE(valueOf("(not 1 < 2)"), 1.0);  // (not 1) < 2
  EXPECT_CLOSE(valueOf("(1 < 2 and 3 < 2 or 1)"), 1.0);  // and/or: one level, left to right
  EXPECT_CLOSE(valueOf("(1 or 1 and 0)"), 0.0);
  std::vector<double> p = {0.5, 0, 0};
  EXPECT_CLOSE(valueOf("(x[1] = 0.5)", p), 1.0);
  EXPECT_CLOSE(valueOf("(x[1] < 0.4)", p), 0.0);
}

struct BuiltinCase {
  const char* expr;
  double expected;
};

TEST(LangConformance, Builtins) {
  const double v = 0.7, w = -2.3;
  const BuiltinCase cases[] = {
      {"sqrt(x[1])", std::sqrt(v)},
      {"exp(x[1])", std::exp(v)},
      {"log(x[1])", std::log(v)},
      {"logd(x[1])", std::log10(v)},
      {"sin(x[2])", std::sin(w)},
      {"cos(x[2])", std::cos(w)},
      {"tan(x[2])", std::tan(w)},
      {"asin(x[1])", std::asin(v)},
      {"acos(x[1])", std::acos(v)},
      {"atan(x[2])", std::atan(w)},
      {"atan2(x[1], x[2])", std::atan2(v, w)},
      {"abs(x[2])", 2.3},
      {"sinh(x[2])", std::sinh(w)},
      {"cosh(x[2])", std::cosh(w)},
      {"tanh(x[2])", std::tanh(w)},
      {"sign(x[2])", -1.0},
      {"sign(x[1])", 1.0},
      {"sign(x[3])", 0.0},
      {"mod(7.4, 3)", 1.0},
      {"mod(x[2] * 3, 4)", std::fmod(-7.0, 4.0)},  // round(-6.9) = -7
      {"mod(2.5, 2)", 1.0},                          // round(2.5) = 3 (ties up)
      {"mod(-2.5, 4)", -2.0},                        // round(-2.5) = -2 (ties up)
      {"max(x[1], x[2])", v},
      {"min(x[1], x[2])", w},
      {"ceil(x[2])", -2.0},
      {"floor(x[2])", -3.0},
      {"int(x[2])", -2.0},
      {"int(2.9)", 2.0},
      {"frac(x[2])", w - std::trunc(w)},
      {"frac(2.75)", 0.75},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.expr);
    EXPECT_CLOSE(valueOf(c.expr, {v, w, 0.0}), c.expected);
  }
}

TEST(LangConformance, BuiltinNamesAreCaseInsensitive) {
  EXPECT_CLOSE(valueOf("SQRT(X[1]) + Max(2, 3)", {4, 0, 0}), 5.0);
}

TEST(LangConformance, DomainConventions) {
  EXPECT_EQ(valueOf("sqrt(-4)"), 0.0);
  EXPECT_EQ(valueOf("sqrt(x[1])", {-4, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("log(x[1])", {0, 0, 0}), std::log(1e-300));
  EXPECT_CLOSE(valueOf("asin(x[1])", {2, 0, 0}), std::asin(1.0));
  EXPECT_TRUE(std::isinf(valueOf("1 / x[1]", {0, 0, 0})));  // IEEE division
  EXPECT_TRUE(std::isnan(valueOf("x[1] ^ 0.5", {-4, 0, 0})));
  EXPECT_TRUE(std::isnan(valueOf("mod(x[1], 0.2)", {5, 0, 0})));  // round(0.2) = 0
}

TEST(LangConformance, NearIntegerExponentIsRepeatedProduct) {
  // hfp treats an exponent within 1e-6 above an integer as that integer.
  EXPECT_CLOSE(valueOf("x[1] ^ 2.0000001", {-3, 0, 0}), 9.0);
  EXPECT_TRUE(std::isnan(valueOf("x[1] ^ 1.9999", {-3, 0, 0})));
}

TEST(LangConformance, Numbers) {
  EXPECT_CLOSE(valueOf("12 + 1.5 + .5 + 2e3 + 2.5E-1 + 1.e1"), 12 + 1.5 + 0.5 + 2000 + 0.25 + 10);
}

TEST(LangConformance, Parameters) {
  Model m = compileOk("my_model(x[2], a[2]) { my_model = a[1] * x[1] + a[2]; }");
  EXPECT_EQ(m.aSize, 2);
  EXPECT_CLOSE(evalModel(m, {3, 0}, {2, 0.5}), 6.5);
}

}  // namespace
}  // namespace frep::lang::testing
