// HyperFun attributes: s[] at the end of the body as expressions, the compiled hfA_* functions
// against their formulas at points, and the diagnostics of wrong calls.
#include <cmath>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

// s[i] of the model at x (parameters 0).
double attributeAt(const Model& m, size_t i, std::vector<double> x) {
  std::vector<Expr> params(static_cast<size_t>(m.aSize), Expr(0.0));
  Expr f = bindParams(m.attributes.at(i), params);
  x.resize(std::max<size_t>(x.size(), static_cast<size_t>(m.xSize)), 0.0);
  auto tape = Tape::compile(f, static_cast<uint32_t>(x.size()));
  PointEvaluator ev;
  return ev.eval(*tape, x.data());
}

TEST(LangAttributes, NoAttributesByDefault) {
  Model m = compileOk("my_model(x[3], a[1]) { my_model = 1 - x[1]*x[1]; }");
  EXPECT_FALSE(m.hasAttributes);
  ASSERT_EQ(m.attributes.size(), 1u);  // hfp's S_dim = 1
  EXPECT_TRUE(m.attributes[0].isConst(0.0));
}

TEST(LangAttributes, AssignedElementsAreExpressions) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    s[1] = 0.5 + 0.25 * x[1];  s[3] = x[2] * x[3];
    my_model = 1 - x[1]*x[1];
  })");
  EXPECT_TRUE(m.hasAttributes);
  ASSERT_EQ(m.attributes.size(), 3u);
  EXPECT_CLOSE(attributeAt(m, 0, {0.4, 2, 3}), 0.6);
  EXPECT_CLOSE(attributeAt(m, 1, {0.4, 2, 3}), 0.0);
  EXPECT_CLOSE(attributeAt(m, 2, {0.4, 2, 3}), 6.0);
}

TEST(LangAttributes, SetColorWhereTheSolidIs) {
  // Red where x[1] >= 0, then blue over it where x[2] >= 0; black elsewhere.
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    d = hfA_SetColor(x[1], s, 1, 0, 0);
    d = hfA_SetColor(x[2], s, 0, 0, 1);
    my_model = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];
  })");
  EXPECT_TRUE(m.hasAttributes);
  auto rgb = [&](double px, double py) {
    return std::vector<double>{attributeAt(m, 0, {px, py, 0}), attributeAt(m, 1, {px, py, 0}),
                               attributeAt(m, 2, {px, py, 0})};
  };
  EXPECT_EQ(rgb(0.5, -0.5), (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(rgb(0.5, 0.5), (std::vector<double>{0, 0, 1}));
  EXPECT_EQ(rgb(-0.5, -0.5), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(rgb(0.0, -0.5), (std::vector<double>{1, 0, 0}));  // f >= 0 colours, f = 0 included
}

TEST(LangAttributes, UnionTakesTheColourOfTheSolidThePointIsIn) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [1, 0, 0];  c2 = [0, 1, 0];
    f1 = 1 - (x[1] + 1)^2 - x[2]^2 - x[3]^2;
    f2 = 1 - (x[1] - 1)^2 - x[2]^2 - x[3]^2;
    my_model = hfA_Union(f1, f2, s, c1, c2, 4);
  })");
  auto f1 = [](double x) { return 1 - (x + 1) * (x + 1); };
  auto f2 = [](double x) { return 1 - (x - 1) * (x - 1); };
  for (double px : {-1.5, -0.5, 0.0, 0.5, 1.5}) {
    double a = f1(px), b = f2(px);
    EXPECT_CLOSE(evalModel(m, {px, 0, 0}), a + b + std::sqrt(a * a + b * b));
  }
  EXPECT_CLOSE(attributeAt(m, 0, {-1.5, 0, 0}), 1.0);  // only in the first
  EXPECT_CLOSE(attributeAt(m, 1, {-1.5, 0, 0}), 0.0);
  EXPECT_CLOSE(attributeAt(m, 0, {1.5, 0, 0}), 0.0);   // only in the second
  EXPECT_CLOSE(attributeAt(m, 1, {1.5, 0, 0}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 0, {0, 0, 0}), 1.0);     // in both (touching): maximum of each
  EXPECT_CLOSE(attributeAt(m, 1, {0, 0, 0}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 0, {5, 0, 0}), 0.0);     // outside the union: s unchanged (0)
}

TEST(LangAttributes, LerpAndCerpMixTwoColours) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [1, 0, 0];  c2 = [0, 0, 1];
    t = hfA_Lerp(s, c1, c2, x[3], -1, 1);
    my_model = t;
  })");
  for (double z : {-2.0, -1.0, -0.5, 0.0, 0.3, 1.0, 3.0}) {
    double t = (z + 1) / 2, tc = std::min(1.0, std::max(0.0, t));
    EXPECT_CLOSE(evalModel(m, {0, 0, z}), t);
    EXPECT_CLOSE(attributeAt(m, 0, {0, 0, z}), 1 - tc);
    EXPECT_CLOSE(attributeAt(m, 2, {0, 0, z}), tc);
  }
  Model c = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [0, 0, 0];  c2 = [1, 1, 1];
    my_model = hfA_Cerp(s, c1, c2, x[3], 0, 1);
  })");
  double t = 0.25, tc = t * t * (3 - 2 * t);
  EXPECT_CLOSE(attributeAt(c, 1, {0, 0, t}), tc);
  EXPECT_CLOSE(evalModel(c, {0, 0, t}), tc);
}

TEST(LangAttributes, ToolboxFunctionValues) {
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {-0.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {0.25, 0, 0}), 0.25);
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {7, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Step(x[1], 2)", {1.9, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Step(x[1], 2)", {2, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {0.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {1.5, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {2.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {2.5, 0, 0}), 0.75 * 0.75 * (3 - 1.5));
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {0, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {4, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Modulo(x[1], 3)", {7.5, 0, 0}), 1.5);
  EXPECT_CLOSE(valueOf("hfA_Modulo(x[1], 3)", {-1, 0, 0}), 2.0);  // a modulo, not a remainder
  EXPECT_CLOSE(valueOf("hfA_Floor(x[1])", {-1.5, 0, 0}), -1.0);   // towards zero, as hfp
  EXPECT_CLOSE(valueOf("hfA_Floor(x[1])", {2.7, 0, 0}), 2.0);
}

TEST(LangAttributes, SetAttributesCopiesWhereInside) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array v[3];
    v = [0.2, 0.4, 0.6];
    d = hfA_SetAttributes(x[1], s, v);
    my_model = 1;
  })");
  EXPECT_CLOSE(attributeAt(m, 0, {1, 0, 0}), 0.2);
  EXPECT_CLOSE(attributeAt(m, 1, {1, 0, 0}), 0.4);
  EXPECT_CLOSE(attributeAt(m, 1, {-1, 0, 0}), 0.0);
}

TEST(LangAttributes, WrongCallsAreErrorsAtTheirPlace) {
  CompileResult r = compile("my_model(x[3], a[1]) {\n  d = hfA_SetColor(x[1], s, 1, 0, 0);\n  my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics[0].line, 2);
  EXPECT_EQ(r.diagnostics[0].column, 26);
  EXPECT_EQ(r.diagnostics[0].message, "hfA_SetColor: 's' needs at least 3 elements, it has 1");
  r = compile("my_model(x[3], a[1], s[3]) {\n  d = hfA_SetColor(x[1], s, 1);\n  my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_SetColor takes 5 arguments, hfA_SetColor(f, s, r, g, b); got 3");
  r = compile("my_model(x[3], a[1], s[3]) {\n array c[3];\n c = [1,1,1];\n"
              " d = hfA_Union(x[1], x[2], s, c, c, x[3]);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_Union: the operation must be a constant 0 to 4");
}

}  // namespace
}  // namespace frep::lang::testing
