// Roerdink's basic set as fr* primitives and the exact path of frMinkowski / frMinkowskiSum /
// frMinkowskiDiff (lang/src/library/fr_minkowski.cpp): no extremum node when every operand is in
// the basic set, the search otherwise; exact values at points.
#include <cmath>

#include "frep/minkowski_algebra/registry.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

double at(const Model& m, std::vector<double> x) { return evalModel(m, std::move(x)); }

const std::string kParts =
    "seg(x[3], a[1]) { seg = frXLine(x, 2); }\n"
    "dsc(x[3], a[1]) { dsc = frZDisc(x, 0.5); }\n"
    "bal(x[3], a[1]) { bal = frBall(x, 0.25); }\n";

TEST(FrMinkowskiAlgebra, MembersAloneAreMinusTheDistance) {
  Model disc = compileOk(kParts + "my_model(x[3], a[1]) { my_model = dsc(x, a); }");
  EXPECT_NEAR(at(disc, {0.2, 0.1, 0}), 0.0, 1e-12);        // on the disc
  EXPECT_NEAR(at(disc, {0.2, 0.1, 0.3}), -0.3, 1e-12);     // above it
  EXPECT_NEAR(at(disc, {0.8, 0, 0.4}), -0.5, 1e-12);       // off the rim: (0.3, 0.4)
  Model seg = compileOk(kParts + "my_model(x[3], a[1]) { my_model = seg(x, a); }");
  EXPECT_NEAR(at(seg, {1, 0, 0}), 0.0, 1e-12);
  EXPECT_NEAR(at(seg, {-0.3, 0.4, 0}), -0.5, 1e-12);
}

TEST(FrMinkowskiAlgebra, BasicSetSumsTakeTheExactPath) {
  // xline(2) ⊕ zdisc(0.5) ⊕ sphere(0.25): a flat stadium plate rounded by 0.25.
  Model m = compileOk(kParts + "my_model(x[3], a[1]) { my_model = frMinkowskiSum(x, seg, dsc, bal); }");
  EXPECT_FALSE(hasExtremum(m.field));
  EXPECT_NEAR(at(m, {1, 0, 0}), 0.25, 1e-12);                // centre: 0.25 below the top
  EXPECT_NEAR(at(m, {1, 0, 0.35}), -0.1, 1e-12);             // above the top
  EXPECT_NEAR(at(m, {2.5 + 0.25 + 0.1, 0, 0}), -0.1, 1e-12);  // beyond the end (rim of the end disc)
  EXPECT_NEAR(at(m, {1, 0.5 + 0.3, 0.4}), 0.25 - 0.5, 1e-12); // beside the straight edge: (0.3, 0.4)
  auto lines = minkowski::describeExact(m.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("error bound 0"), std::string::npos) << lines[0];
  // Two-operand frMinkowski, nested: the same solid.
  Model n = compileOk(kParts +
                      "sd(x[3], a[1]) { sd = frMinkowski(x, seg, dsc); }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowski(x, sd, bal); }");
  EXPECT_FALSE(hasExtremum(n.field));
  EXPECT_TRUE(n.field.same(m.field));
}

TEST(FrMinkowskiAlgebra, OtherOperandsFallBackToTheSearch) {
  Model m = compileOk(kParts +
                      "blob(x[3], a[1]) { blob = 0.04 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowski(x, bal, blob); }");
  EXPECT_TRUE(hasExtremum(m.field));
  EXPECT_GT(at(m, {0.44, 0, 0}), -1e-3);
  EXPECT_LT(at(m, {0.47, 0, 0}), 0);
  Model b = compileOk(kParts +
                      "dx(x[3], a[1]) { dx = frXDisc(x, 0.5); }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowski(x, dsc, bal) | frMinkowski(x, dx, bal); }");
  EXPECT_FALSE(hasExtremum(b.field));
  // Discs along two axes (a bidisc) are exact too, and so are a sphere on top of them (a
  // bicircle-sphere) and discs on three axes (tricircle-sphere): the convex-projection field.
  Model bi = compileOk(kParts +
                       "dx(x[3], a[1]) { dx = frXDisc(x, 0.5); }\n"
                       "my_model(x[3], a[1]) { my_model = frMinkowski(x, dsc, dx); }");
  EXPECT_FALSE(hasExtremum(bi.field));
  Model bs = compileOk(kParts +
                       "dx(x[3], a[1]) { dx = frXDisc(x, 0.5); }\n"
                       "bd(x[3], a[1]) { bd = frMinkowski(x, dsc, dx); }\n"
                       "my_model(x[3], a[1]) { array o[2]; o = [0, 0.01]; my_model = frMinkowski(x, bd, bal, o); }");
  EXPECT_FALSE(hasExtremum(bs.field));
  // Over the flat faces: the xdisc face at x = 0.5 (the zdisc's reach) and the zdisc face at
  // z = 0.5, each 0.25 further out by the ball.
  EXPECT_NEAR(at(bs, {1.0, 0.1, 0.2}), -0.25, 1e-12);
  EXPECT_NEAR(at(bs, {0.1, -0.2, 1.5}), -0.75, 1e-12);
  EXPECT_NEAR(at(bs, {0, 0, 0}), 0.25 + 0.5, 1e-12);  // inside: ball + inradius (γ = 0)
  Model tri = compileOk(kParts +
                        "dx(x[3], a[1]) { dx = frXDisc(x, 0.5); }\n"
                        "dy(x[3], a[1]) { dy = frYDisc(x, 0.3); }\n"
                        "blk(x[3], a[1]) { blk = frBlock(x, 2, 1, 1); }\n"
                        "my_model(x[3], a[1]) { my_model = frMinkowskiSum(x, blk, dsc, dx, dy, bal); }");
  EXPECT_FALSE(hasExtremum(tri.field));
  auto lines = minkowski::describeExact(tri.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("error bound 0"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("26 primitives"), std::string::npos) << lines[0];
  // Beyond the block along x: the x face is the block's face ⊕ the xdisc (0.5) at 2 + 0.5 + 0.3.
  EXPECT_NEAR(at(tri, {2 + 0.8 + 0.25 + 0.4, 0.5, 0.5}), -0.4, 1e-12);
  EXPECT_NEAR(at(tri, {1, 0.5, 0.5}), 0.25 + 0.8, 1e-12);  // in the block: ball + inradius min(0.8, 1, 0.8)
}

TEST(FrMinkowskiAlgebra, SubtractionChainsAreExact) {
  // ((block 4^3 ⊖ sphere 0.25) ⊖ xline 2) = block ⊖ (sphere ⊕ xline), eq. 19–20: x in
  // [-2 + 0.25, 2 - 0.25 - 2], y, z in [-1.75, 1.75].
  Model m = compileOk(kParts +
                      "blk(x[3], a[1]) { array c[3]; c = [-2, -2, -2]; blk = frBlock(x, 4, 4, 4, c); }\n"
                      "e1(x[3], a[1]) { e1 = frMinkowskiDiff(x, blk, bal); }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, e1, seg); }");
  EXPECT_FALSE(hasExtremum(m.field));
  EXPECT_NEAR(at(m, {-1, 0, 0}), 0.75, 1e-12);
  EXPECT_NEAR(at(m, {-0.15, 0, 0}), -0.1, 1e-12);
  EXPECT_NEAR(at(m, {-1, 1.85, 0}), -0.1, 1e-12);
  // A sphere eroded by a segment: {X : both ends of X + seg within radius 2}.
  Model s = compileOk(kParts +
                      "big(x[3], a[1]) { big = frBall(x, 2); }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, big, seg); }");
  EXPECT_FALSE(hasExtremum(s.field));
  EXPECT_NEAR(at(s, {-1, 0, 0}), 1.0, 1e-12);  // ends at -1 and 1
  EXPECT_LT(at(s, {0.1, 0, 0}), 0);            // end at 2.1
}

TEST(FrMinkowskiAlgebra, BadArgumentsAreNamed) {
  CompileResult r = compile("my_model(x[3], a[1]) { my_model = frXDisc(x, -1); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("frXDisc: the radius must be >= 0"), std::string::npos) << allDiagnostics(r);
  r = compile("my_model(x[3], a[1]) { array c[2]; c = [0, 0]; my_model = frBall(x, 1, c); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("must have 3 elements"), std::string::npos) << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
