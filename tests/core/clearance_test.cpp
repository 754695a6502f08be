// Certified clearance and penetration depth (relations/clearance.h) on pairs whose distance and
// depth have closed forms: the exact value must lie within the stated bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/relations/clearance.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

Expr ball(double cx, double cy, double cz, double r) {
  return r * r - square(X - cx) - square(Y - cy) - square(Z - cz);
}
// Box [lo, hi] as the exact min of its six slabs.
Expr block(std::array<double, 3> lo, std::array<double, 3> hi) {
  return min(min(min(X - lo[0], hi[0] - X), min(Y - lo[1], hi[1] - Y)), min(Z - lo[2], hi[2] - Z));
}

std::vector<Interval> cube(double lo, double hi) { return {{lo, hi}, {lo, hi}, {lo, hi}}; }

// The exact distance lies in [lower, upper], the bound is as tight as asked, and the witnesses
// are points of their solids exactly upper apart.
void expectClearance(const Expr& a, const Expr& b, double exact, double tol) {
  TapePtr ta = Tape::compile(a, 3), tb = Tape::compile(b, 3);
  auto box = cube(-3, 4);
  ClearanceOptions o;
  o.tolerance = tol;
  ClearanceResult r = clearance(*ta, *tb, box.data(), o);
  EXPECT_TRUE(r.converged) << r.lower << " " << r.upper << " pairs " << r.pairs;
  EXPECT_LE(r.lower, exact) << "pairs " << r.pairs;
  EXPECT_GE(r.upper, exact - 1e-12);  // witnesses are tested in double precision
  EXPECT_LE(r.upper - r.lower, tol);
  ASSERT_EQ(r.a.size(), 3u);
  ASSERT_EQ(r.b.size(), 3u);
  PointEvaluator pe;
  EXPECT_GE(pe.eval(*ta, r.a.data()), 0.0);
  EXPECT_GE(pe.eval(*tb, r.b.data()), 0.0);
  EXPECT_DOUBLE_EQ(std::hypot(r.a[0] - r.b[0], r.a[1] - r.b[1], r.a[2] - r.b[2]), r.upper);
}

void expectDepth(const Expr& a, const Expr& b, double exact, double tol) {
  auto box = cube(-3, 4);
  PenetrationOptions o;
  o.tolerance = tol;
  PenetrationResult r = penetration(a, b, 3, box.data(), o);
  EXPECT_TRUE(r.converged) << r.lower << " " << r.upper << " boxes " << r.boxes;
  EXPECT_LE(r.lower, exact) << "boxes " << r.boxes;
  EXPECT_GE(r.upper, exact);
  EXPECT_LE(r.upper - r.lower, tol);
  ASSERT_EQ(r.translation.size(), 3u);
  EXPECT_NEAR(std::hypot(r.translation[0], r.translation[1], r.translation[2]), r.upper, 1e-12);
}

}  // namespace

TEST(Clearance, TwoBalls) { expectClearance(ball(-2, 0, 0, 1), ball(2, 0, 0, 1), 2.0, 1e-3); }

TEST(Clearance, BallAndBox) {
  expectClearance(ball(0, 0, 0, 1), block({2, -1, -1}, {3, 1, 1}), 1.0, 1e-3);
  // Nearest to the box's edge: the ball at (0, 0, 0) and the box [1, 2] x [1, 2] x [-1, 1]
  // are sqrt(2) - 0.5 apart (edge x = y = 1).
  expectClearance(ball(0, 0, 0, 0.5), block({1, 1, -1}, {2, 2, 1}), std::sqrt(2.0) - 0.5, 1e-3);
}

TEST(Clearance, BoxesAtOffsets) {
  const Expr unit = block({0, 0, 0}, {1, 1, 1});
  expectClearance(unit, block({1.5, 0, 0}, {2.5, 1, 1}), 0.5, 1e-3);                        // face to face
  expectClearance(unit, block({2, 2, 0.5}, {3, 3, 1.5}), std::sqrt(2.0), 1e-3);             // edge to edge
  expectClearance(unit, block({2, 2.5, 3}, {3, 3.5, 4}), std::sqrt(1 + 2.25 + 4.0), 1e-3);  // corners
}

TEST(Clearance, OverlapHasZeroLowerBound) {
  TapePtr ta = Tape::compile(ball(-0.5, 0, 0, 1), 3), tb = Tape::compile(ball(0.5, 0, 0, 1), 3);
  auto box = cube(-3, 4);
  ClearanceResult r = clearance(*ta, *tb, box.data(), ClearanceOptions{});
  EXPECT_EQ(r.lower, 0.0);
  EXPECT_LE(r.upper, 1e-3);
}

TEST(Clearance, EmptySolid) {
  TapePtr ta = Tape::compile(ball(0, 0, 0, 1), 3), tb = Tape::compile(ball(10, 0, 0, 1), 3);
  auto box = cube(-3, 4);
  ClearanceResult r = clearance(*ta, *tb, box.data(), ClearanceOptions{});
  EXPECT_TRUE(r.emptyB);
  EXPECT_FALSE(r.converged);
}

// A ball of radius 0.4 at (0.6, 0.5, 0.5), inside the box [0, 2] x [0, 1] x [0, 1], leaves it
// soonest through a face y or z: depth 0.5 + 0.4 (distance to the face plus the radius).
TEST(Penetration, BallInsideBox) { expectDepth(ball(0.6, 0.5, 0.5, 0.4), block({0, 0, 0}, {2, 1, 1}), 0.9, 2e-3); }

// A unit ball at the origin reaching 0.5 into the box [0.5, 3] x [-2, 2]^2.
TEST(Penetration, BallIntoBox) { expectDepth(ball(0, 0, 0, 1), block({0.5, -2, -2}, {3, 2, 2}), 0.5, 2e-3); }

// Two unit balls 1.6 apart: depth 2 - 1.6.
TEST(Penetration, TwoBalls) { expectDepth(ball(-0.8, 0, 0, 1), ball(0.8, 0, 0, 1), 0.4, 2e-3); }
