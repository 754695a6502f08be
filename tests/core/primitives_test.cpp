// Core primitives: values at centres, on surfaces and outside, against their formulas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/primitives/primitives.h"

using namespace frep;

namespace {

double at(const Expr& e, std::vector<double> p) {
  TapePtr t = Tape::compile(e, static_cast<uint32_t>(p.size()));
  PointEvaluator pe;
  return pe.eval(*t, p.data());
}

int sgn(double v) { return (v > 0) - (v < 0); }

std::vector<std::vector<double>> randomPoints(int n, double lo, double hi, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<std::vector<double>> pts;
  for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  return pts;
}

}  // namespace

TEST(Primitives, Sphere) {
  Expr s = sphere({1.0, 2.0, 3.0}, 2.0);
  EXPECT_EQ(at(s, {1, 2, 3}), 4.0);
  EXPECT_EQ(at(s, {3, 2, 3}), 0.0);
  EXPECT_EQ(at(s, {1, 2, 1}), 0.0);
  EXPECT_EQ(at(s, {1, 5, 3}), -5.0);
  EXPECT_EQ(at(ball({0.0, 0.0, 0.0, 0.0}, 1.0), {0.5, 0.5, 0.5, 0.5}), 0.0);  // 4D ball
}

TEST(Primitives, Ellipsoid) {
  Expr e = ellipsoid({0.0, 0.0, 1.0}, {1.0, 2.0, 4.0});
  EXPECT_EQ(at(e, {0, 0, 1}), 1.0);
  EXPECT_EQ(at(e, {1, 0, 1}), 0.0);
  EXPECT_EQ(at(e, {0, 2, 1}), 0.0);
  EXPECT_EQ(at(e, {0, 0, 5}), 0.0);
  EXPECT_EQ(at(e, {0, 4, 1}), -3.0);
  EXPECT_THROW(ellipsoid({0.0, 0.0, 0.0}, {1.0, 0.0, 1.0}), std::invalid_argument);
}

TEST(Primitives, BlockExactMinAndSqrtSystemAgreeInSign) {
  Expr b1 = block({1.0, 0.0, 0.0}, {1.0, 2.0, 3.0});
  EXPECT_EQ(at(b1, {1, 0, 0}), 1.0);   // centre: the smallest half size
  EXPECT_EQ(at(b1, {2, 0, 0}), 0.0);   // face
  EXPECT_EQ(at(b1, {2, 2, 3}), 0.0);   // corner
  EXPECT_EQ(at(b1, {1, 0, 4}), -1.0);  // outside
  Expr b0 = block({1.0, 0.0, 0.0}, {1.0, 2.0, 3.0}, 0.0);
  EXPECT_EQ(at(b0, {2, 0, 0}), 0.0);
  EXPECT_EQ(at(b0, {1, 2, 0}), 0.0);
  for (auto& p : randomPoints(1000, -4.0, 4.0, 1)) {
    double m = std::min({1.0 - std::fabs(p[0] - 1), 2.0 - std::fabs(p[1]), 3.0 - std::fabs(p[2])});
    EXPECT_EQ(at(b1, p), m);
    EXPECT_EQ(sgn(at(b0, p)), sgn(m)) << p[0] << " " << p[1] << " " << p[2];
  }
}

TEST(Primitives, Cylinders) {
  Coords3 c = {1.0, 2.0, 3.0};
  EXPECT_EQ(at(cylinderX(c, 2.0), {100, 2, 3}), 4.0);
  EXPECT_EQ(at(cylinderX(c, 2.0), {-7, 4, 3}), 0.0);
  EXPECT_EQ(at(cylinderY(c, 2.0), {1, -50, 5}), 0.0);
  EXPECT_EQ(at(cylinderZ(c, 2.0), {3, 2, 9}), 0.0);
  EXPECT_EQ(at(cylinderZ(c, 2.0), {1, 5, 0}), -5.0);
  EXPECT_EQ(at(ellipticCylinderX(c, 2.0, 4.0), {9, 4, 3}), 0.0);
  EXPECT_EQ(at(ellipticCylinderX(c, 2.0, 4.0), {9, 2, 7}), 0.0);
  EXPECT_EQ(at(ellipticCylinderY(c, 2.0, 4.0), {3, 9, 3}), 0.0);
  EXPECT_EQ(at(ellipticCylinderY(c, 2.0, 4.0), {1, 9, 7}), 0.0);
  EXPECT_EQ(at(ellipticCylinderZ(c, 2.0, 4.0), {1, 6, 9}), 0.0);
  EXPECT_EQ(at(ellipticCylinderZ(c, 2.0, 4.0), {1, 2, 9}), 1.0);
}

TEST(Primitives, DoubleCones) {
  Coords3 c = {0.0, 0.0, 1.0};
  EXPECT_EQ(at(coneZ(c, 0.5), {0, 0, 1}), 0.0);      // apex
  EXPECT_EQ(at(coneZ(c, 0.5), {0, 0, 3}), 4.0);      // on the axis
  EXPECT_EQ(at(coneZ(c, 0.5), {1, 0, 3}), 0.0);      // radius 0.5 per unit height
  EXPECT_EQ(at(coneZ(c, 0.5), {0, -1, -1}), 0.0);    // the lower nappe
  EXPECT_LT(at(coneZ(c, 0.5), {1, 0, 1.5}), 0.0);
  EXPECT_EQ(at(coneX(c, 2.0), {1, 2, 1}), 0.0);
  EXPECT_EQ(at(coneY(c, 2.0), {0, 1, 3}), 0.0);
}

TEST(Primitives, Tori) {
  Coords3 c = {1.0, 0.0, 0.0};
  EXPECT_EQ(at(torusZ(c, 2.0, 0.5), {3, 0, 0}), 0.25);      // tube centre
  EXPECT_EQ(at(torusZ(c, 2.0, 0.5), {3.5, 0, 0}), 0.0);     // outer equator
  EXPECT_EQ(at(torusZ(c, 2.0, 0.5), {1, 2, 0.5}), 0.0);     // top of the tube
  EXPECT_EQ(at(torusZ(c, 2.0, 0.5), {1, 0, 0}), 0.25 - 4);  // hole centre
  EXPECT_EQ(at(torusX(c, 2.0, 0.5), {1, 0, 2}), 0.25);
  EXPECT_EQ(at(torusY(c, 2.0, 0.5), {3, 0.5, 0}), 0.0);
}

TEST(Primitives, SuperellipsoidContainsTheEllipsoidCase) {
  Coords3 c = {0.5, 0.0, 0.0}, r = {1.0, 2.0, 1.5};
  Expr s = superellipsoid(c, r, 1.0, 1.0), e = ellipsoid(c, r);
  for (auto& p : randomPoints(200, -2.0, 2.0, 2)) EXPECT_NEAR(at(s, p), at(e, p), 1e-14);
  // s = 0.5: |x|^4 + |y|^4 + |z|^4 <= 1, boxier than the ball.
  Expr box = superellipsoid({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 0.5, 0.5);
  EXPECT_NEAR(at(box, {0.8, 0.8, 0}), 1 - 2 * std::pow(0.8, 4), 1e-15);
  EXPECT_EQ(at(box, {0, 0, 1}), 0.0);
  EXPECT_THROW(superellipsoid(c, r, 0.0, 1.0), std::invalid_argument);
}

TEST(Primitives, HalfSpace) {
  Expr h = halfSpace({0.0, 0.0, 2.0}, 4.0);  // z <= 2
  EXPECT_EQ(at(h, {5, 5, 2}), 0.0);
  EXPECT_EQ(at(h, {0, 0, 0}), 4.0);
  EXPECT_EQ(at(h, {0, 0, 3}), -2.0);
}

TEST(Primitives, TwoDimensional) {
  Expr d = disc({1.0, 1.0}, 1.0), r = rectangle({0.0, 0.0}, {2.0, 1.0});
  EXPECT_EQ(numVars(d), 2u);
  EXPECT_EQ(numVars(r), 2u);
  EXPECT_EQ(at(d, {1, 1}), 1.0);
  EXPECT_EQ(at(d, {2, 1}), 0.0);
  EXPECT_EQ(at(r, {0, 0}), 1.0);
  EXPECT_EQ(at(r, {2, 0.5}), 0.0);
  EXPECT_EQ(at(r, {0, 3}), -2.0);
  EXPECT_EQ(at(rectangle({0.0, 0.0}, {2.0, 1.0}, 0.0), {2, 0.5}), 0.0);
}
