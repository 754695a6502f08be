// Collision of animated perturbation freeforms (Vyatkin-Perturbation: perturbations eq. 10 whose
// coefficients change with time; collision by recursive subdivision), as frIntersects runs it
// over a box in space and time. Two unit balls 2.4 apart each grow a bump towards the other,
// height 0.7 t (frPerturbQuadric, ellipsoid of radius 0.6 centred on the ball's surface). On the
// axis, at the midpoint x = 1.2, ball A's field is 1 - 1.44 + 0.7 t (1 - (0.2/0.6)^2)^3, zero at
// t* = 0.44 / (0.7 (8/9)^3): the bumps first touch there (the closed form checked), so a time
// window ending before t* is proved collision-free and one ending after it is not.
#include <cmath>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

double relationOver(double t0, double t1) {
  const std::string window = std::to_string(t0) + ", " + std::to_string(t1);
  Model m = compileOk(
      "pa(x[4], a[1]) { array c[3], r[3], h[1]; c = [1, 0, 0]; r = [0.6, 0.6, 0.6]; h = [0.7 * x[4]];\n"
      "  pa = frPerturbQuadric(x, 1 - x[1]^2 - x[2]^2 - x[3]^2, c, r, h); }\n"
      "pb(x[4], a[1]) { array c[3], r[3], h[1]; c = [1.4, 0, 0]; r = [0.6, 0.6, 0.6]; h = [0.7 * x[4]];\n"
      "  pb = frPerturbQuadric(x, 1 - (x[1] - 2.4)^2 - x[2]^2 - x[3]^2, c, r, h); }\n"
      "my_model(x[3], a[1]) { array o[8]; o = [-1.5, 3.9, -1.5, 1.5, -1.5, 1.5, " +
      window + "]; my_model = frIntersects(pa, pb, o); }");
  return m.field.isConst() ? m.field.constValue() : NAN;
}

TEST(PerturbationCollision, AnimatedBumpsFirstTouchAtTheClosedFormTime) {
  const double tStar = 0.44 / (0.7 * std::pow(8.0 / 9.0, 3));
  EXPECT_EQ(relationOver(0.0, tStar - 0.002), 0.0);  // proved disjoint over the whole window
  EXPECT_EQ(relationOver(0.0, tStar + 0.002), 1.0);  // a common point in space and time
  EXPECT_EQ(relationOver(tStar + 0.01, 1.0), 1.0);
}

}  // namespace
}  // namespace frep::lang::testing
