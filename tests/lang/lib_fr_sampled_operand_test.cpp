// frMinkowski / frMinkowskiDiff method 2: an operand with no exact form (here hfEllipsoid with
// equal axes, a ball the library does not recognise) meshed on a grid and summed by the exact
// paths (minkowski_algebra/sampled_operand.h). Values against the true distance within the
// sampled operand's stated bound; the report line states it; bad uses are errors at the call.
#include <cmath>
#include <random>
#include <regex>

#include "frep/minkowski_algebra/registry.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const std::string kShapes =
    "ell(x[3], a[1]) { array c[3]; c = [0.1, 0, -0.05]; ell = hfEllipsoid(x, c, 0.5, 0.5, 0.5); }\n"
    "b(x[3], a[1]) { b = frBall(x, 0.15); }\n"
    "blk(x[3], a[1]) { array v[3]; v = [-0.1, -0.1, -0.1]; blk = hfBlock(x, v, 0.2, 0.2, 0.2); }\n";

double statedBound(const Expr& f) {
  const auto lines = minkowski::describeExact(f);
  EXPECT_EQ(lines.size(), 1u);
  std::smatch m;
  if (lines.empty() || !std::regex_search(lines[0], m, std::regex("error bound ([0-9.e+-]+) \\(the sampled operand's")))
    return -1;
  return std::stod(m[1]);
}

TEST(FrSampledOperand, CurvedOperandPlusBallIsWithinTheStatedBound) {
  Model sum = compileOk(kShapes + "my_model(x[3], a[1]) { array o[2]; o = [2, 48]; my_model = frMinkowski(x, ell, b, o); }");
  Model diff = compileOk(kShapes + "my_model(x[3], a[1]) { array o[2]; o = [2, 48]; my_model = frMinkowskiDiff(x, ell, b, o); }");
  for (const Model* m : {&sum, &diff}) {
    EXPECT_FALSE(hasExtremum(m->field));
    const double bound = statedBound(m->field);
    ASSERT_GT(bound, 0);
    EXPECT_LT(bound, 0.05);  // about a voxel of the 48^3 grid over the ellipsoid's box
    const double R = m == &sum ? 0.65 : 0.35;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 400; ++i) {
      const double p[3] = {u(rng), u(rng), u(rng)};
      const double truth = R - std::sqrt((p[0] - 0.1) * (p[0] - 0.1) + p[1] * p[1] + (p[2] + 0.05) * (p[2] + 0.05));
      const double f = evalModel(*m, {p[0], p[1], p[2]});
      if (std::fabs(truth) > bound + 1e-9) EXPECT_EQ(f >= 0, truth > 0) << p[0] << " " << p[1] << " " << p[2];
      // Where the field is exact (outside the sum, inside the difference) it is the distance to a
      // surface within `bound` of the true one.
      if ((m == &sum && f < 0) || (m == &diff && f > 0)) EXPECT_NEAR(f, truth, bound + 1e-9);
    }
  }
  // The box operand first, the sampled one second: the sum commutes.
  Model boxFirst = compileOk(kShapes + "my_model(x[3], a[1]) { array o[2]; o = [2, 48]; my_model = frMinkowski(x, blk, ell, o); }");
  EXPECT_FALSE(hasExtremum(boxFirst.field));
  EXPECT_GT(evalModel(boxFirst, {0.1 + 0.55, 0.0, -0.05}), 0);  // beyond the ellipsoid, within the box's reach
}

TEST(FrSampledOperand, BadUsesAreErrorsAtTheOptions) {
  const std::string torus = "tor(x[3], a[1]) { array c[3]; c = [0, 0, 0]; tor = hfTorusZ(x, c, 0.1, 0.3); }\n";
  CompileResult noConvex = compile(kShapes + torus + "m(x[3], a[1]) { array o[2]; o = [2, 32]; m = frMinkowski(x, ell, tor, o); }", "m.hf");
  ASSERT_FALSE(noConvex.ok);
  EXPECT_NE(allDiagnostics(noConvex).find("method 2 needs the other operand"), std::string::npos) << allDiagnostics(noConvex);
  CompileResult badRes = compile(kShapes + "m(x[3], a[1]) { array o[2]; o = [2, 7.5]; m = frMinkowski(x, ell, b, o); }", "m.hf");
  ASSERT_FALSE(badRes.ok);
  EXPECT_NE(allDiagnostics(badRes).find("a whole number from 8 to 1024"), std::string::npos) << allDiagnostics(badRes);
  CompileResult notHere = compile(kShapes + "m(x[3], a[1]) { array o[2]; o = [2, 32]; m = frMinkowskiSum(x, ell, b, o); }", "m.hf");
  ASSERT_FALSE(notHere.ok);
  EXPECT_NE(allDiagnostics(notHere).find("2 (sampled operand: frMinkowski, frMinkowskiDiff)"), std::string::npos) << allDiagnostics(notHere);
}

}  // namespace
}  // namespace frep::lang::testing
