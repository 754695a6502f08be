// Point membership, box classification, Newton projection and the subdivision intersection
// test (Vyatkin-Perturbation, collision detection) on spheres with exact answers.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "frep/relations/relations.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

// Ball of radius r centred at (cx, 0, 0): r^2 - |X - C|^2 (exact in binary for these inputs).
TapePtr ball(double cx, double r) {
  return Tape::compile(r * r - square(X - cx) - square(Y) - square(Z), 3);
}

std::vector<Interval> cube(double lo, double hi) { return {{lo, hi}, {lo, hi}, {lo, hi}}; }

}  // namespace

TEST(Relations, PointMembership) {
  auto t = ball(0.0, 1.0);
  const double in[3] = {0.5, 0.0, 0.0}, on[3] = {0.0, 1.0, 0.0}, out[3] = {0.0, 0.0, 1.5};
  EXPECT_EQ(classifyPoint(*t, in, 1e-9), Membership::In);
  EXPECT_EQ(classifyPoint(*t, on, 1e-9), Membership::On);
  EXPECT_EQ(classifyPoint(*t, out, 1e-9), Membership::Out);
  // The tolerance band: f(0.5, 0, 0) = 0.75 is On with tol 0.75, In below it.
  EXPECT_EQ(classifyPoint(*t, in, 0.75), Membership::On);
  EXPECT_EQ(classifyPoint(*t, in, 0.7499), Membership::In);
  // f(0, 0, 1.5) = -1.25.
  EXPECT_EQ(classifyPoint(*t, out, 1.25), Membership::On);
  // A domain error (NaN) is never In or On.
  auto nan = Tape::compile(Expr(0.0) / (X - X) + 0.0 * Y, 2);
  const double p[2] = {1.0, 1.0};
  EXPECT_EQ(classifyPoint(*nan, p, 1.0), Membership::Out);
}

TEST(Relations, BoxClassification) {
  auto t = ball(0.0, 1.0);
  auto inner = cube(-0.25, 0.25);   // f >= 1 - 3/16 > 0
  auto outer = cube(1.0, 2.0);      // f <= 1 - 3 < 0
  auto across = cube(0.5, 1.5);     // contains (0.5,0.5,0.5) inside and (1.5,..) outside
  EXPECT_EQ(classifyBox(*t, inner.data()), BoxClass::Inside);
  EXPECT_EQ(classifyBox(*t, outer.data()), BoxClass::Outside);
  EXPECT_EQ(classifyBox(*t, across.data()), BoxClass::Ambiguous);
  // A box whose corner touches the sphere is not Outside (the solid is closed).
  std::vector<Interval> touching = {{1.0, 2.0}, {0.0, 1.0}, {0.0, 1.0}};
  EXPECT_EQ(classifyBox(*t, touching.data()), BoxClass::Ambiguous);
}

TEST(Relations, ProjectToSurfaceLandsOnTheSphere) {
  auto t = ball(0.0, 2.0);
  double x[3] = {3.0, -1.0, 0.5};
  const double norm = std::sqrt(10.25);
  const double f = projectToSurface(*t, x, 20, 1e-13);
  EXPECT_LE(std::fabs(f), 1e-13);
  EXPECT_NEAR(x[0], 2.0 * 3.0 / norm, 1e-13);  // Newton moves along the radial gradient
  EXPECT_NEAR(x[1], -2.0 / norm, 1e-13);
  EXPECT_NEAR(x[2], 2.0 * 0.5 / norm, 1e-13);
  // From inside too.
  double y[3] = {0.1, 0.2, -0.3};
  projectToSurface(*t, y, 30, 1e-13);
  EXPECT_NEAR(std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]), 2.0, 1e-13);
}

TEST(Relations, ProjectStopsWhereTheGradientVanishes) {
  auto t = ball(0.0, 1.0);
  double x[3] = {0.0, 0.0, 0.0};  // the centre: grad = 0, no direction
  EXPECT_EQ(projectToSurface(*t, x, 10), 1.0);
  EXPECT_EQ(x[0], 0.0);
  EXPECT_EQ(x[1], 0.0);
  EXPECT_EQ(x[2], 0.0);
}

TEST(Relations, OverlappingSpheresIntersectWithAWitness) {
  auto a = ball(-0.5, 1.0), b = ball(0.5, 1.0);
  // The box is off-centre, so the witness is found below the root box.
  std::vector<Interval> box = {{-2.0, 3.0}, {-1.5, 2.5}, {-2.0, 2.0}};
  auto r = mayIntersect(*a, *b, box.data(), 1e-3);
  ASSERT_EQ(r.contact, Contact::Intersecting);
  ASSERT_EQ(r.witness.size(), 3u);
  PointEvaluator pe;
  EXPECT_GE(pe.eval(*a, r.witness.data()), 0.0);
  EXPECT_GE(pe.eval(*b, r.witness.data()), 0.0);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(box[i].contains(r.witness[i]));
  EXPECT_GT(r.boxesVisited, 1u);
}

TEST(Relations, SeparatedSpheresAreDisjoint) {
  auto a = ball(-1.5, 1.0), b = ball(1.5, 1.0);  // gap of 1 between the surfaces
  // Off-centre in x, so that no split plane falls on the symmetry plane x = 0 (a split there
  // would separate the spheres at once).
  std::vector<Interval> box = {{-3.0, 3.3}, {-3.0, 3.0}, {-3.0, 3.0}};
  auto r = mayIntersect(*a, *b, box.data(), 1e-2);
  EXPECT_EQ(r.contact, Contact::Disjoint);
  EXPECT_TRUE(r.witness.empty());
  // A narrower gap (0.02) needs finer boxes but is still proved.
  auto c = ball(-1.01, 1.0), d = ball(1.01, 1.0);
  EXPECT_EQ(mayIntersect(*c, *d, box.data(), 1e-3).contact, Contact::Disjoint);
  // Too coarse a minimum size for that gap leaves the question open.
  EXPECT_EQ(mayIntersect(*c, *d, box.data(), 0.5).contact, Contact::Unknown);
}

TEST(Relations, TouchingSpheres) {
  auto a = ball(-1.0, 1.0), b = ball(1.0, 1.0);  // the only common point is the origin
  // A box centred on the origin: its centre is the contact point, where fa = fb = 0 exactly.
  auto centred = cube(-2.0, 2.0);
  auto r = mayIntersect(*a, *b, centred.data(), 1e-2);
  ASSERT_EQ(r.contact, Contact::Intersecting);
  EXPECT_EQ(r.witness, (std::vector<double>{0.0, 0.0, 0.0}));
  // Otherwise no box centre ever hits the single contact point, and no box around it can be
  // proved empty: subdivision cannot decide tangency.
  std::vector<Interval> box = {{-2.0, 3.0}, {-2.0, 2.0}, {-2.0, 2.0}};
  EXPECT_EQ(mayIntersect(*a, *b, box.data(), 0.05).contact, Contact::Unknown);
}

TEST(Relations, SolidOutsideTheBoxIsDisjoint) {
  auto a = ball(0.0, 1.0), b = ball(5.0, 1.0);
  auto box = cube(-1.0, 1.0);  // b does not reach into this box at all
  auto r = mayIntersect(*a, *b, box.data(), 1e-3);
  EXPECT_EQ(r.contact, Contact::Disjoint);
  EXPECT_EQ(r.boxesVisited, 1u);
}
