// Statements, arrays, loops, branches, objects and library calls, lowered and evaluated.
#include <cmath>

#include "frep/lang/library/library.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

// Fake library functions (the real hf* library is tested in hflib_*_test.cpp).
const bool kRegistered = registerAll({
    {"testShiftX", "AS", "xt[1] -= d",
     [](std::vector<Arg>& args) {
       auto& xt = *args[0].array;
       if (xt.empty()) throw LibraryError("array " + args[0].name + " is empty", 0);
       xt[0] = xt[0] - args[1].value;
       return Expr(1.0);
     }},
    {"testBall", "AAS", "R^2 - |x - c|^2 (3D)",
     [](std::vector<Arg>& args) {
       auto& x = *args[0].array;
       auto& c = *args[1].array;
       if (c.size() != 3) throw LibraryError("center must have 3 elements", 1);
       Expr r = square(args[2].value);
       for (int i = 0; i < 3; ++i) r = r - square(x[i] - c[i]);
       return r;
     }},
});

TEST(LangStatements, ScalarsAndCaseInsensitiveNames) {
  Model m = compileOk(R"(My_Model(x[3], a[1]) {
    R = 2;  r2 = r*R;
    MY_MODEL = r2 - X[1]*x[1];
  })");
  EXPECT_EQ(m.objectName, "my_model");
  EXPECT_CLOSE(evalModel(m, {1.5, 0, 0}), 4 - 2.25);
}

TEST(LangStatements, ArraysElementsAndLiterals) {
  Model m = compileOk(R"(m(x[3], a[1]) {
    array v[3], w[2];
    v = [1, -2, 3.5];
    w[1] = v[3] * 2;
    w[2] = v[1];
    m = w[1] + w[2] + v[2];
  })");
  EXPECT_CLOSE(evalModel(m, {0, 0, 0}), 7.0 + 1.0 - 2.0);
}

TEST(LangStatements, FractionalIndexRoundsToNearestTiesUp) {
  Model m = compileOk(R"(m(x[3], a[1]) {
    array v[3];
    v = [10, 20, 30];
    v[1.5] = 7;       -- ties up: element 2
    m = v[1.4] + v[2] + v[2.6] * 100;   -- 10 + 7 + 3000
  })");
  EXPECT_CLOSE(evalModel(m, {0, 0, 0}), 3017.0);
}

TEST(LangStatements, ArrayLiteralWithExpressions) {
  Model m = compileOk(R"(m(x[2], a[1]) {
    array c[2];
    c = [x[1] * 2, -1.5];
    m = c[1] + c[2];
  })");
  EXPECT_CLOSE(evalModel(m, {3, 0}), 4.5);
}

TEST(LangStatements, WhileLoopUnrollsNineTerms) {
  // HyperFun's sample style: a 9-term sum built by a while loop.
  Model m = compileOk(R"(blobs(x[3], a[1]) {
    array cx[9];
    i = 1;
    while i <= 9 loop
      cx[i] = i - 5;
      i = i + 1;
    endloop;
    sum = 0;
    j = 1;
    while (j < 10) loop
      sum = sum + exp(-((x[1] - cx[j])^2 + x[2]^2 + x[3]^2));
      j = j + 1;
    endloop;
    blobs = sum - 0.5;
  })");
  double p[3] = {0.3, -0.2, 0.1}, expected = 0;
  for (int k = 1; k <= 9; ++k)
    expected += std::exp(-((p[0] - (k - 5)) * (p[0] - (k - 5)) + p[1] * p[1] + p[2] * p[2]));
  EXPECT_CLOSE(evalModel(m, {p[0], p[1], p[2]}), expected - 0.5);
  EXPECT_EQ(numVars(m.field), 3u);
}

TEST(LangStatements, NestedLoops) {
  Model m = compileOk(R"(m(x[1], a[1]) {
    s1 = 0; i = 0;
    while i < 4 loop
      j = 0;
      while j < i loop s1 = s1 + 1; j = j + 1; endloop;
      i = i + 1;
    endloop;
    m = s1 * x[1];
  })");
  EXPECT_CLOSE(evalModel(m, {2}), 12.0);  // 0+1+2+3 = 6, times 2
}

TEST(LangStatements, FixedParametersLetLoopsDependOnA) {
  const char* src = R"(m(x[1], a[2]) {
    i = 0; acc = 0;
    while i < a[1] loop acc = acc + x[1]; i = i + 1; endloop;
    m = acc + a[2];
  })";
  CompileResult r = compile(src, "p.hf");
  EXPECT_FALSE(r.ok);  // a[1] unknown at compile time
  CompileOptions opt;
  opt.params = {4};    // a[2] stays a parameter
  Model m = compileOk(src, opt);
  EXPECT_EQ(numParams(m.field), 2u);
  EXPECT_CLOSE(evalModel(m, {1.5}, {0, 10}), 4 * 1.5 + 10);
}

TEST(LangStatements, FixedParametersBelongToTheSelectedObjectOnly) {
  CompileOptions opt;
  opt.params = {100};
  Model m = compileOk(R"(
    f(x[1], a[1]) { f = a[1]; }
    my_model(x[1], a[1]) {
      array q[1];
      q[1] = 7;
      my_model = f(x, q) + a[1];
    })", opt);
  EXPECT_CLOSE(evalModel(m, {0}), 107.0);
}

TEST(LangStatements, ConstantIfPicksOneBranch) {
  Model m = compileOk(R"(m(x[1], a[1]) {
    k = 3;
    if k > 2 and not (k = 4) then v = 1; else v = 2; endif;
    if k < 0 then w = 5; endif;
    m = v * x[1];
  })");
  EXPECT_CLOSE(evalModel(m, {7}), 7.0);
  EXPECT_EQ(nodeCount(m.field), 1u);  // just x[0]: no select left
}

TEST(LangStatements, IfOnXBecomesSelect) {
  Model m = compileOk(R"(m(x[2], a[1]) {
    array v[2];
    v = [0, 0];
    r = 1;
    if x[1] > 0 then
      r = x[1] * 2;  v[2] = 5;
    else
      r = -x[1];
    endif;
    m = r + v[2];
  })");
  EXPECT_CLOSE(evalModel(m, {3, 0}), 11.0);
  EXPECT_CLOSE(evalModel(m, {-3, 0}), 3.0);
  EXPECT_CLOSE(evalModel(m, {0, 0}), 0.0);
  bool hasSelect = false;
  forEachNode(m.field, [&](const Node& n) { hasSelect |= n.op == Op::Select; });
  EXPECT_TRUE(hasSelect);
}

TEST(LangStatements, IfOnXWithEqualityTolerance) {
  Model m = compileOk(R"(m(x[1], a[1]) {
    m = 1;
    if x[1] = 2 then m = 5; endif;
  })");
  EXPECT_CLOSE(evalModel(m, {2.0000005}), 5.0);
  EXPECT_CLOSE(evalModel(m, {2.01}), 1.0);
}

TEST(LangStatements, BranchVariableUsedOnlyInsideIsFine) {
  Model m = compileOk(R"(m(x[1], a[1]) {
    m = 0;
    if x[1] < 0 then t = x[1] * x[1]; m = t; endif;
  })");
  EXPECT_CLOSE(evalModel(m, {-2}), 4.0);
  EXPECT_CLOSE(evalModel(m, {2}), 0.0);
}

TEST(LangStatements, LoopInsideBranchOnX) {
  Model m = compileOk(R"(m(x[1], a[1]) {
    acc = 0;
    if x[1] > 0 then
      i = 0;
      while i < 3 loop acc = acc + x[1]; i = i + 1; endloop;
    else
      acc = 1;
    endif;
    m = acc;
  })");
  EXPECT_CLOSE(evalModel(m, {2}), 6.0);
  EXPECT_CLOSE(evalModel(m, {-2}), 1.0);
}

TEST(LangStatements, LibraryCallMutatesArrayInPlace) {
  Model m = compileOk(R"(m(x[3], a[1]) {
    array xt[3], c[3];
    xt = [x[1], x[2], x[3]];
    c = [0, 0, 0];
    d = testShiftX(xt, 2);
    m = testBall(xt, c, 1);
  })");
  EXPECT_CLOSE(evalModel(m, {2.5, 0.5, 0}), 1 - 0.25 - 0.25);
}

TEST(LangStatements, LibraryCallMutatesXItself) {
  // hfp semantics: transformations change x for the rest of the object.
  Model m = compileOk(R"(m(x[3], a[1]) {
    array c[3];
    c = [0, 0, 0];
    d = TESTSHIFTX(x, 1);
    m = testBall(x, c, 2) + x[1];
  })");
  EXPECT_CLOSE(evalModel(m, {1, 1, 0}), (4 - 0 - 1) + 0.0);
}

TEST(LangStatements, OperandsEvaluateRightToLeft) {
  // As in hfp, the right operand (and its mutation) is evaluated first.
  Model m = compileOk(R"(m(x[1], a[1]) {
    m = x[1] + testShiftX(x, 10);
  })");
  EXPECT_CLOSE(evalModel(m, {3}), 3 - 10 + 1.0);
}

TEST(LangStatements, LibraryErrorBecomesDiagnosticAtArgument) {
  CompileResult r = compile(R"(m(x[3], a[1]) {
    array c[2];
    c = [0, 0];
    m = testBall(x, c, 1);
  })", "lib.hf");
  ASSERT_FALSE(r.ok);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].line, 4);
  EXPECT_EQ(r.diagnostics[0].column, 21);
  EXPECT_EQ(r.diagnostics[0].message, "testBall: center must have 3 elements");
}

TEST(LangStatements, MultipleObjectsAndCalls) {
  const char* src = R"(
    Box(x[3], a[2]) { Box = a[1] - abs(x[1]) & a[2] - abs(x[2]); }
    Shifted(x[3], a[1]) {
      array p[2], xt[3];
      p = [1, 2];
      xt = [x[1] - a[1], x[2], x[3]];
      Shifted = Box(xt, p);
    }
    third(x[3], a[1]) { third = x[3]; }
  )";
  CompileResult r = compile(src, "multi.hf");
  ASSERT_TRUE(r.ok) << allDiagnostics(r);
  ASSERT_EQ(r.objects.size(), 3u);
  EXPECT_EQ(r.objects[0].name, "box");
  EXPECT_EQ(r.objects[0].aSize, 2);
  EXPECT_EQ(r.objects[1].line, 3);
  EXPECT_EQ(r.model.objectName, "box");  // no my_model: the first

  CompileOptions opt;
  opt.object = "SHIFTED";
  Model m = compileOk(src, opt);
  EXPECT_EQ(m.objectName, "shifted");
  EXPECT_EQ(m.aSize, 1);
  // Box(xt, p) at x = (3.5, 0.5) with a[1] = 3: xt = (0.5, 0.5). hfp precedence puts - and &
  // on one level: ((1 - 0.5) & 2) - 0.5.
  double e = (0.5 + 2 - std::sqrt(0.25 + 4)) - 0.5;
  EXPECT_CLOSE(evalModel(m, {3.5, 0.5, 0}, {3}), e);
  EXPECT_EQ(numParams(m.field), 1u);
}

TEST(LangStatements, CallWithAttributeArray) {
  Model m = compileOk(R"(
    col(x[2], a[1], s[2]) { s[1] = 0.5; col = x[1] - a[1]; }
    my_model(x[2], a[1], s[2]) { my_model = col(x, a, s) * 2; }
  )");
  EXPECT_CLOSE(evalModel(m, {3, 0}, {1}), 4.0);
  CompileResult bad = compile(R"(
    col(x[2], a[1], s[2]) { col = 1; }
    my_model(x[2], a[1], s[3]) { my_model = col(x, a, s); }
  )", "s.hf");
  EXPECT_FALSE(bad.ok);
  ASSERT_EQ(bad.diagnostics.size(), 1u);
  EXPECT_EQ(bad.diagnostics[0].message, "object 'col' expects s[2], but 's' has 3 elements");
}

TEST(LangStatements, CallPassesCallersParametersAndCoordinates) {
  // The callee's a[] are the caller's x and its x are the caller's a: substitution is
  // simultaneous, not one after the other.
  Model m = compileOk(R"(
    f(x[2], a[2]) { f = x[1] * 10 + x[2] + a[1] * 1000 + a[2] * 100; }
    my_model(x[2], a[2]) { my_model = f(a, x); }
  )");
  EXPECT_CLOSE(evalModel(m, {1, 2}, {3, 4}), 3 * 10 + 4 + 1 * 1000 + 2 * 100);
}

TEST(LangStatements, SelectionPrefersMyModelThenWarnsOnUnknownName) {
  const char* src = "a1(x[1], a[1]) { a1 = 1; }\nmy_model(x[1], a[1]) { my_model = 2; }\n";
  CompileResult r = compile(src, "sel.hf");
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.model.objectName, "my_model");
  CompileOptions opt;
  opt.object = "nothere";
  r = compile(src, "sel.hf", opt);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.model.objectName, "my_model");
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].severity, Diagnostic::Severity::Warning);
  EXPECT_EQ(r.diagnostics[0].message, "no object named 'nothere'; using 'my_model'");
}

// hfA_SetColor is compiled (lang_attributes_test.cpp); the Perlin-noise textures (hfA_Turbulence) warn.
TEST(LangStatements, AttributeFunctionsWarnOnceAndKeepGeometry) {
  CompileResult r = compile(R"(m(x[3], a[1], s[3]) {
    m = x[1];
    d = hfA_SetColor(m, s, 1, 0, 0);
    d = HFA_Turbulence(m, s, 2);
    s[2] = 0.5;
    s = [1, 2, 3];
  })", "attr.hf");
  ASSERT_TRUE(r.ok) << allDiagnostics(r);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].severity, Diagnostic::Severity::Warning);
  EXPECT_EQ(r.diagnostics[0].line, 4);
  EXPECT_EQ(r.objects[0].sSize, 3);
  EXPECT_CLOSE(evalModel(r.model, {0.25, 0, 0}), 0.25);
}

TEST(LangStatements, RealLibraryShiftThenSphere) {
  if (!findLibraryFunction("hfSphere") || !findLibraryFunction("hfShift3D"))
    GTEST_SKIP() << "hf library not linked";
  Model m = compileOk(R"(my_model(x[3], a[1]) {
    array c[3], xt[3];
    c = [0, 0, 0];
    xt = [x[1], x[2], x[3]];
    d = hfShift3D(xt, 1, 2, 0);
    my_model = hfSphere(xt, c, a[1]);
  })");
  // (x - (1, 2, 0)) at (1.5, 2, 0.5): R^2 - 0.25 - 0 - 0.25
  EXPECT_CLOSE(evalModel(m, {1.5, 2, 0.5}, {2}), 4 - 0.5);
}

TEST(LangStatements, CarriageReturnsAreAccepted) {
  Model m = compileOk("m(x[1], a[1])\r\n{\r\n  m = x[1] + 1;\r\n}\r\n");
  EXPECT_CLOSE(evalModel(m, {1}), 2.0);
}

TEST(LangStatements, SourceHashIdentifiesTheText) {
  CompileResult a = compile("m(x[1], a[1]) { m = 1; }", "h.hf");
  CompileResult b = compile("m(x[1], a[1]) { m = 2; }", "h.hf");
  CompileResult c = compile("m(x[1], a[1]) { m = 1; }", "other.hf");
  EXPECT_NE(a.model.sourceHash, b.model.sourceHash);
  EXPECT_EQ(a.model.sourceHash, c.model.sourceHash);
}

TEST(LangStatements, CompileFileReadsAndReportsMissingFiles) {
  std::string path = ::testing::TempDir() + "lang_model.hf";
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("m(x[2], a[1]) { m = x[2]; }\n", f);
    std::fclose(f);
  }
  CompileResult r = compileFile(path);
  ASSERT_TRUE(r.ok) << allDiagnostics(r);
  EXPECT_CLOSE(evalModel(r.model, {0, 4}), 4.0);
  r = compileFile(path + ".missing");
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(), path + ".missing: error: cannot open file");
}

}  // namespace
}  // namespace frep::lang::testing
