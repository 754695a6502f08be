// Intersections of half-spaces recognised as convex polytopes (convex_polytope.h), and their
// Minkowski sums with a ball by the exact offset path: values against the exact distance to the
// polytope (closed forms at points whose nearest feature is a face, an edge or a vertex).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/distance_offset.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/minkowski_algebra/basic_set.h"
#include "frep/minkowski_algebra/reduction.h"
#include "frep/primitives/ops.h"

using namespace frep;

namespace {

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

// The regular tetrahedron {|x| + ... } with vertices (h, h, -h)... : four planes x +- y +- z <= h
// with an even number of minus signs, written with unnormalised normals (|n| = sqrt 3).
Expr tetrahedron(double h) {
  return min(min(h - (X() + Y() + Z()), h - (X() - Y() - Z())), min(h - (-X() + Y() - Z()), h - (-X() - Y() + Z())));
}

double eval(const Expr& e, double x, double y, double z) {
  TapePtr t = Tape::compile(e, 3);
  PointEvaluator pe;
  const double p[3] = {x, y, z};
  return pe.eval(*t, p);
}

}  // namespace

TEST(ConvexPolytope, TetrahedronIsRecognisedWithItsExactDistance) {
  const double h = 0.5;
  auto p = minkowski::convexPolytopeOf(tetrahedron(h));
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->planes, 4u);
  EXPECT_EQ(p->facets, 4u);
  EXPECT_EQ(p->vertices, 4u);
  // The vertices solve three of the planes: (-h, -h, -h) is one (x+y+z = -3h <= h, ...).
  // Beyond it along (-1, -1, -1) the nearest feature is the vertex: distance |X - v|.
  EXPECT_NEAR(eval(p->field, -h - 0.3, -h - 0.3, -h - 0.3), -0.3 * std::sqrt(3.0), 1e-12);
  // Inside, the distance is the nearest face plane's: at the centre h / sqrt 3.
  EXPECT_NEAR(eval(p->field, 0, 0, 0), h / std::sqrt(3.0), 1e-12);
  // Outside a face, the plane distance: from the centre along the face normal (1, 1, 1)/sqrt 3.
  const double d = 0.05, c = (h / std::sqrt(3.0) + d) / std::sqrt(3.0);
  EXPECT_NEAR(eval(p->field, c, c, c), -d, 1e-12);
  // The same set as the min of planes everywhere (signs at random points).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int i = 0; i < 2000; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    const double a = eval(tetrahedron(h), x, y, z), b = eval(p->field, x, y, z);
    if (std::abs(a) > 1e-9) EXPECT_EQ(a > 0, b > 0) << x << " " << y << " " << z;
  }
}

TEST(ConvexPolytope, RFunctionsAndScaledPlanesAreRecognisedOthersAreNot) {
  // A box written with R-functions (a = 0) and planes scaled by 2: min/max form, then planes.
  const Expr slabX = rIntersection(2.0 * (0.5 - X()), 0.5 + X(), 0.0);
  const Expr box = rIntersection(rIntersection(slabX, min(0.4 - Y(), 0.4 + Y()), 0.0), min(0.3 - Z(), 0.3 + Z()), 0.0);
  auto p = minkowski::convexPolytopeOf(box);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->facets, 6u);
  EXPECT_EQ(p->vertices, 8u);
  EXPECT_NEAR(eval(p->field, 0.7, 0.6, 0.5), -std::sqrt(0.04 + 0.04 + 0.04), 1e-12);  // nearest: a corner
  // Three planes (unbounded), a curved leaf, and a union are not polytopes.
  EXPECT_FALSE(minkowski::convexPolytopeOf(min(min(X(), Y()), Z())).has_value());
  EXPECT_FALSE(minkowski::convexPolytopeOf(min(min(min(X(), Y()), Z()), 1.0 - X() * X())).has_value());
  EXPECT_FALSE(minkowski::convexPolytopeOf(max(tetrahedron(0.5), tetrahedron(0.2) - 1.0)).has_value());
  // Empty: x >= 1 and x <= 0 (with two more planes).
  EXPECT_FALSE(minkowski::convexPolytopeOf(min(min(X() - 1.0, -X()), min(Y(), Z()))).has_value());
}

TEST(ConvexPolytope, SumWithABallIsTheOffsetOfTheExactDistance) {
  // tetrahedron ⊕ ball r: r - dist(X, T), exact at a point beyond a vertex (where the min of
  // the plane distances would be wrong: it is the largest plane distance, not the vertex's).
  const double h = 0.5, r = 0.2;
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Sphere;
  s.size[0] = r;
  const Expr ball = r * r - X() * X() - Y() * Y() - Z() * Z();
  minkowski::ExactTerm t;
  t.sum = minkowski::sumOf(s);
  t.pieces = 1;
  minkowski::registerExact(ball, t);
  Expr sum;
  ASSERT_TRUE(minkowski::distanceBallSum(tetrahedron(h), ball, 3, &sum));
  const double far = 0.25;  // beyond the vertex (-h, -h, -h) by `far` along each axis
  EXPECT_NEAR(eval(sum, -h - far, -h - far, -h - far), r - far * std::sqrt(3.0), 1e-12);
  EXPECT_GT(eval(sum, -h - 0.1, -h - 0.1, -h - 0.1), 0);  // 0.173 from the vertex: in the sum
  EXPECT_LT(eval(min(sum, Expr(1.0)), -h - 0.2, -h - 0.2, -h - 0.2), 0);  // 0.346: outside
  const auto described = minkowski::describeExact(sum);
  ASSERT_FALSE(described.empty());
  EXPECT_NE(described[0].find("convex polytope of 4 facets"), std::string::npos) << described[0];
}
