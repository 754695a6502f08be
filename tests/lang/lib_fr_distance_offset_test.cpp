// Minkowski sum / difference of an exact signed distance (here the cube of six flat Bezier
// patches, a closed mesh) and a ball: the offset path of frMinkowski / frMinkowskiSum /
// frMinkowskiDiff (minkowski_algebra/distance_offset.h). Values against the analytic distance to
// the cube, signs against the certified search on the same solid, and the cases that must
// still search. Files (.stl, open meshes, .vdb volumes): tests/cli/unit/geometry_files_test.cpp.
#include <algorithm>
#include <cmath>
#include <random>

#include "frep/minkowski_algebra/registry.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const std::string kCube = kBezierCube +
    "ball(x[3], a[1]) { array c[3]; c = [0.1, -0.05, 0.2]; ball = frBall(x, 0.25, c); }\n"
    "b2(x[3], a[1]) { b2 = frBall(x, 0.15); }\n";

// Signed distance to [0, 1]^3, positive inside.
double cubeDistance(double x, double y, double z) {
  const double p[3] = {x, y, z};
  double out2 = 0, in = 1e300;
  for (double v : p) {
    const double d = std::max(0.0, std::max(-v, v - 1));
    out2 += d * d;
    in = std::min(in, std::min(v, 1 - v));
  }
  return out2 > 0 ? -std::sqrt(out2) : in;
}

std::vector<std::array<double, 3>> randomPoints(int n, double lo, double hi) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<std::array<double, 3>> p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

TEST(FrDistanceOffset, MeshPlusBallIsTheOffsetOfTheDistance) {
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowski(x, cube, ball); }");
  EXPECT_FALSE(hasExtremum(m.field));
  auto lines = minkowski::describeExact(m.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("exact Minkowski sum"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("error bound 0"), std::string::npos) << lines[0];
  // f(x) = d_cube(x - c) + r; outside the sum it is minus the exact distance to the sum.
  for (const auto& p : randomPoints(2000, -0.8, 1.8))
    EXPECT_NEAR(evalModel(m, {p[0], p[1], p[2]}), cubeDistance(p[0] - 0.1, p[1] + 0.05, p[2] - 0.2) + 0.25, 1e-9);
  // The ball first: the same field.
  Model b = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowski(x, ball, cube); }");
  EXPECT_TRUE(b.field.same(m.field));
}

TEST(FrDistanceOffset, SignsEqualTheCertifiedSearch) {
  // The same ball as a formula (not a basic-set member): the search runs, with its box given.
  Model fast = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowski(x, cube, ball); }");
  Model search = compileOk(kCube +
                           "fb(x[3], a[1]) { fb = 0.0625 - (x[1] - 0.1)^2 - (x[2] + 0.05)^2 - (x[3] - 0.2)^2; }\n"
                           "my_model(x[3], a[1]) { array o[8]; o = [0, 0.001, -0.15, 0.35, -0.3, 0.2, -0.05, 0.45];\n"
                           "  my_model = frMinkowski(x, cube, fb, o); }");
  ASSERT_TRUE(hasExtremum(search.field));
  int compared = 0;
  for (const auto& p : randomPoints(150, -0.5, 1.5)) {
    const double f = evalModel(fast, {p[0], p[1], p[2]});
    if (std::fabs(f) < 0.01) continue;  // within the search's tolerance of the boundary
    EXPECT_EQ(f >= 0, evalModel(search, {p[0], p[1], p[2]}) >= 0) << p[0] << " " << p[1] << " " << p[2];
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

TEST(FrDistanceOffset, DifferenceErodesByTheInsideDistance) {
  // {x : x + ball(c, r) ⊆ cube} = [r, 1 - r]^3 - c.
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, cube, ball); }");
  EXPECT_FALSE(hasExtremum(m.field));
  auto lines = minkowski::describeExact(m.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("exact Minkowski difference"), std::string::npos) << lines[0];
  for (const auto& p : randomPoints(2000, -0.5, 1.5)) {
    const double f = evalModel(m, {p[0], p[1], p[2]});
    EXPECT_NEAR(f, cubeDistance(p[0] + 0.1, p[1] - 0.05, p[2] + 0.2) - 0.25, 1e-9);
    bool in = true;
    const double q[3] = {p[0] + 0.1, p[1] - 0.05, p[2] + 0.2};
    for (double v : q) in = in && v >= 0.25 && v <= 0.75;
    if (std::fabs(f) > 1e-9) EXPECT_EQ(f >= 0, in);
  }
}

TEST(FrDistanceOffset, ChainsOfBallsStayOnThePath) {
  // (cube ⊕ ball) ⊕ b2 = cube ⊕ ball(0.4): exact outside after the first sum.
  Model two = compileOk(kCube + "cb(x[3], a[1]) { cb = frMinkowski(x, cube, ball); }\n"
                                "my_model(x[3], a[1]) { my_model = frMinkowski(x, cb, b2); }");
  Model sum = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowskiSum(x, cube, ball, b2); }");
  EXPECT_FALSE(hasExtremum(two.field));
  EXPECT_FALSE(hasExtremum(sum.field));
  for (const auto& p : randomPoints(500, -0.8, 1.8)) {
    const double want = cubeDistance(p[0] - 0.1, p[1] + 0.05, p[2] - 0.2) + 0.4;
    EXPECT_NEAR(evalModel(two, {p[0], p[1], p[2]}), want, 1e-9);
    EXPECT_NEAR(evalModel(sum, {p[0], p[1], p[2]}), want, 1e-9);
  }
  // (cube ⊖ ball) ⊖ b2 = cube ⊖ ball(0.4): exact inside after the first difference.
  Model e = compileOk(kCube + "cb(x[3], a[1]) { cb = frMinkowskiDiff(x, cube, ball); }\n"
                              "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, cb, b2); }");
  EXPECT_FALSE(hasExtremum(e.field));
  EXPECT_NEAR(evalModel(e, {0.4, 0.55, 0.3}), cubeDistance(0.5, 0.5, 0.5) - 0.4, 1e-9);
}

TEST(FrDistanceOffset, WhatIsNotExactSearches) {
  const std::string opts = "array o[2]; o = [0, 0.05]; ";
  // A sum's result is exact only outside: eroding it searches; so does a ball minus the cube.
  Model a = compileOk(kCube + "cb(x[3], a[1]) { cb = frMinkowski(x, cube, ball); }\n"
                              "my_model(x[3], a[1]) { " + opts + "my_model = frMinkowskiDiff(x, cb, b2, o); }");
  EXPECT_TRUE(hasExtremum(a.field));
  Model b = compileOk(kCube + "my_model(x[3], a[1]) { " + opts + "my_model = frMinkowskiDiff(x, ball, cube, o); }");
  EXPECT_TRUE(hasExtremum(b.field));
  // A sheared reading of the distance is not recognised (only translations are, and a
  // polyhedral mesh's scalings: the polytopes it bounds, below).
  Model c = compileOk(kCube + "sc(x[3], a[1]) { array y[3]; y = [x[1] + x[2], x[2], x[3]]; sc = cube(y, a); }\n"
                              "my_model(x[3], a[1]) { " + opts + "my_model = frMinkowski(x, sc, b2, o); }");
  EXPECT_TRUE(hasExtremum(c.field));
  // The cube's flat patches read through a scaling bound the box [0, 0.5] x [0, 1]^2: exact.
  Model s = compileOk(kCube + "sc(x[3], a[1]) { array y[3]; y = [2 * x[1], x[2], x[3]]; sc = cube(y, a); }\n"
                              "my_model(x[3], a[1]) { my_model = frMinkowski(x, sc, b2); }");
  EXPECT_FALSE(hasExtremum(s.field));
  EXPECT_NEAR(evalModel(s, {0.8, 0.5, 0.5}), -0.3 + 0.15, 1e-9);
  EXPECT_NEAR(evalModel(s, {0.7, 1.2, -0.1}), -std::sqrt(0.04 + 0.04 + 0.01) + 0.15, 1e-9);
  // A translated one is.
  Model d = compileOk(kCube + "sh(x[3], a[1]) { array y[3]; y = [x[1] - 2, x[2], x[3] + 1]; sh = cube(y, a); }\n"
                              "my_model(x[3], a[1]) { my_model = frMinkowski(x, sh, b2); }");
  EXPECT_FALSE(hasExtremum(d.field));
  EXPECT_NEAR(evalModel(d, {2.5, 0.5, -0.5}), 0.5 + 0.15, 1e-9);
}

TEST(FrDistanceOffset, HyperFunTorusAndCylinderOffsetByTheirExactDistances) {
  // hfTorusZ's polynomial and hfCylinderZ's R^2 - rho^2 keep their HyperFun values, but a ball
  // sum or difference reads them as their exact distances: r0 -+ r tubes and R -+ r cylinders.
  const std::string shapes =
      "tor(x[3], a[1]) { array c[3]; c = [0.1, 0, 0]; tor = hfTorusZ(x, c, 0.6, 0.2); }\n"
      "cyl(x[3], a[1]) { array c[3]; c = [0, 0.2, 0]; cyl = hfCylinderZ(x, c, 0.3); }\n"
      "b(x[3], a[1]) { b = frBall(x, 0.15); }\n";
  Model tor = compileOk(shapes + "my_model(x[3], a[1]) { my_model = tor(x, a); }");
  EXPECT_NEAR(evalModel(tor, {0.7, 0.0, 0.1}), 0.04 - 0.01 - 0.0, 1e-12);  // r0^2 - |p|^2 - R^2 + 2 R rho
  Model sum = compileOk(shapes + "my_model(x[3], a[1]) { my_model = frMinkowski(x, tor, b); }");
  Model diff = compileOk(shapes + "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, tor, b); }");
  Model cyl = compileOk(shapes + "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, cyl, b); }");
  for (const Model* m : {&sum, &diff, &cyl}) {
    EXPECT_FALSE(hasExtremum(m->field));
    ASSERT_EQ(minkowski::describeExact(m->field).size(), 1u);
  }
  for (const auto& p : randomPoints(1000, -1.0, 1.0)) {
    const double rho = std::hypot(p[0] - 0.1, p[1]), tube = std::hypot(rho - 0.6, p[2]);
    EXPECT_NEAR(evalModel(sum, {p[0], p[1], p[2]}), 0.35 - tube, 1e-9);
    EXPECT_NEAR(evalModel(diff, {p[0], p[1], p[2]}), 0.05 - tube, 1e-9);
    EXPECT_NEAR(evalModel(cyl, {p[0], p[1], p[2]}), 0.15 - std::hypot(p[0], p[1] - 0.2), 1e-9);
  }
  // A spindle torus (R < r0) has no such distance: the search runs.
  Model spindle = compileOk("t(x[3], a[1]) { array c[3]; c = [0, 0, 0]; t = hfTorusZ(x, c, 0.1, 0.3); }\n"
                            "b(x[3], a[1]) { b = frBall(x, 0.15); }\n"
                            "my_model(x[3], a[1]) { array o[8]; o = [0, 0.01, -0.2, 0.2, -0.2, 0.2, -0.2, 0.2];\n"
                            "  my_model = frMinkowski(x, t, b, o); }");
  EXPECT_TRUE(hasExtremum(spindle.field));
}

}  // namespace
}  // namespace frep::lang::testing
