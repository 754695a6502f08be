// The tree-walking interpreter, and the compiled models checked against it point by point.
#include <cmath>

#include "frep/lang/frontend/interpret.h"
#include "frep/lang/library/library.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

TEST(LangInterpret, EvaluatesLoopsBranchesAndCalls) {
  const char* src = R"(
    Box(x[3], a[2]) { Box = (a[1] - abs(x[1])) & (a[2] - abs(x[2])); }
    my_model(x[3], a[1]) {
      array p[2], c[9];
      p = [1, 2];
      i = 1;
      while i <= 9 loop c[i] = i * a[1]; i = i + 1; endloop;
      if x[3] > 0 then r = Box(x, p); else r = c[9] - x[1]^2; endif;
      my_model = r | sign(x[2]) * mod(7.6, 3);
    })";
  Interpreter in(src);
  Model m = compileOk(src);
  EXPECT_EQ(in.objectName(), "my_model");
  for (std::vector<double> x : {std::vector<double>{0.3, -0.7, 1.1}, {1.5, 0.2, -2}, {0, 0, 0}}) {
    double a = 0.5;
    EXPECT_CLOSE(in.eval(x, {a}), evalModel(m, x, {a}));
  }
  // A hand-computed point: x3 < 0, so r = 9a - x1^2 = 4.5 - 2.25; then r | (1 * 2).
  double r = 4.5 - 2.25;
  EXPECT_CLOSE(in.eval({1.5, 0.2, -2}, {0.5}), r + 2 + std::sqrt(r * r + 4));
}

TEST(LangInterpret, LibraryCallsMutateArrays) {
  if (!findLibraryFunction("hfShift3D") || !findLibraryFunction("hfSphere"))
    GTEST_SKIP() << "hf library not linked";
  const char* src = R"(my_model(x[3], a[1]) {
    array c[3];
    c = [0, 0, 0];
    d = hfShift3D(x, 1, 0, 0);
    my_model = hfSphere(x, c, 2) + x[1];
  })";
  Interpreter in(src);
  EXPECT_CLOSE(in.eval({1.5, 1, 0}, {0}), (4 - 0.25 - 1) + 0.5);
}

TEST(LangInterpret, RejectsModelsThatDoNotCompile) {
  EXPECT_THROW(Interpreter("m(x[1], a[1]) { m = q; }"), InterpretError);
}

}  // namespace
}  // namespace frep::lang::testing
