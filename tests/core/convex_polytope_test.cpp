// Intersections of half-spaces recognised as convex polytopes (convex_polytope.h), and their
// Minkowski sums with a ball by the exact offset path: values against the exact distance to the
// polytope (closed forms at points whose nearest feature is a face, an edge or a vertex).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

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

// A ball of radius r at the origin, registered as the basic-set sphere frBall / hfSphere make.
Expr registeredBall(double r) {
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Sphere;
  s.size[0] = r;
  const Expr ball = r * r - X() * X() - Y() * Y() - Z() * Z();
  minkowski::ExactTerm t;
  t.sum = minkowski::sumOf(s);
  t.pieces = 1;
  minkowski::registerExact(ball, t);
  return ball;
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
  const Expr ball = registeredBall(r);
  Expr sum;
  ASSERT_TRUE(minkowski::distanceBallSum(tetrahedron(h), ball, 3, &sum));
  const double far = 0.25;  // beyond the vertex (-h, -h, -h) by `far` along each axis
  EXPECT_NEAR(eval(sum, -h - far, -h - far, -h - far), r - far * std::sqrt(3.0), 1e-12);
  EXPECT_GT(eval(sum, -h - 0.1, -h - 0.1, -h - 0.1), 0);                  // 0.173 from the vertex: in the sum
  EXPECT_LT(eval(min(sum, Expr(1.0)), -h - 0.2, -h - 0.2, -h - 0.2), 0);  // 0.346: outside
  const auto described = minkowski::describeExact(sum);
  ASSERT_FALSE(described.empty());
  EXPECT_NE(described[0].find("convex polytope of 4 facets"), std::string::npos) << described[0];
}

namespace {

// The exact distance from p to the box [lo, hi] outside it (0 inside).
double boxOutsideDistance(const double p[3], const double lo[3], const double hi[3]) {
  double s = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    s += d * d;
  }
  return std::sqrt(s);
}

// The box [lo, hi] as the min of its six planes (HyperFun's hfBlock in min/max form).
Expr block(const double lo[3], const double hi[3]) {
  const Expr c[3] = {X(), Y(), Z()};
  Expr e;
  for (int a = 0; a < 3; ++a) {
    const Expr slab = min(c[a] - lo[a], hi[a] - c[a]);
    e = a == 0 ? slab : min(e, slab);
  }
  return e;
}

}  // namespace

// An L-shaped slab written as a block minus a block (the HyperFun way: s1 \ s2) is the union
// of two boxes: the normal form keeps the two non-empty terms of block1 ∩ (outside one plane of
// block2), and the field is the exact distance to their union outside it.
TEST(PolytopeUnion, BlockMinusBlockIsAUnionOfBoxesWithTheExactOutsideDistance) {
  const double lo1[3] = {-1, -1, -0.25}, hi1[3] = {1, 1, 0.25};
  const double lo2[3] = {-0.2, -0.2, -1}, hi2[3] = {1.3, 1.3, 1};
  const Expr slab = rIntersection(block(lo1, hi1), -block(lo2, hi2), 0.0);
  EXPECT_FALSE(minkowski::convexPolytopeOf(slab).has_value());
  auto u = minkowski::polytopeUnionOf(slab);
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(u->pieces, 2u);
  EXPECT_EQ(u->boxes, 2u);
  // The pieces: x in [-1, -0.2] (full y), y in [-1, -0.2] (full x); they overlap in a corner.
  const double pa[2][3] = {{-1, -1, -0.25}, {-1, -1, -0.25}}, pb[2][3] = {{-0.2, 1, 0.25}, {1, -0.2, 0.25}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-1.6, 1.6);
  int outside = 0;
  for (int i = 0; i < 4000; ++i) {
    const double p[3] = {coord(rng), coord(rng), coord(rng)};
    const double f = eval(u->field, p[0], p[1], p[2]), original = eval(slab, p[0], p[1], p[2]);
    if (std::abs(original) > 1e-9) EXPECT_EQ(f > 0, original > 0) << p[0] << " " << p[1] << " " << p[2];
    const double d = std::min(boxOutsideDistance(p, pa[0], pb[0]), boxOutsideDistance(p, pa[1], pb[1]));
    if (d > 0) {
      ++outside;
      EXPECT_NEAR(f, -d, 1e-12) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(outside, 2000);
  // In the notch (inside the second block), the nearest point is on the first piece's face
  // x = -0.2: not a distance to the second block's planes (0.2 or 0.3 from the point).
  EXPECT_NEAR(eval(u->field, 0.3, 0.4, 0), -0.5, 1e-12);
}

// A tetrahedron minus a block that takes its upper half leaves one general piece, the same
// polytope as the tetrahedron cut by z <= 0: the same exact distance inside and out.
TEST(PolytopeUnion, GeneralPiecesKeepTheExactDistanceOfTheirPolytope) {
  const double lo[3] = {-2, -2, 0}, hi[3] = {2, 2, 2};
  auto u = minkowski::polytopeUnionOf(min(tetrahedron(0.5), -block(lo, hi)));
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(u->pieces, 1u);
  EXPECT_EQ(u->boxes, 0u);
  auto cut = minkowski::convexPolytopeOf(min(tetrahedron(0.5), -Z()));
  ASSERT_TRUE(cut.has_value());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-1.2, 1.2);
  for (int i = 0; i < 1000; ++i) {
    const double x = coord(rng), y = coord(rng), z = coord(rng);
    EXPECT_NEAR(eval(u->field, x, y, z), eval(cut->field, x, y, z), 1e-12) << x << " " << y << " " << z;
  }
}

TEST(PolytopeUnion, UnboundedEmptyCurvedAndOversizedFormsAreRefused) {
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, big[3] = {2, 2, 2}, nbig[3] = {-2, -2, -2};
  EXPECT_FALSE(minkowski::polytopeUnionOf(max(block(lo, hi), X())).has_value());  // a half-space
  EXPECT_FALSE(
      minkowski::polytopeUnionOf(max(tetrahedron(0.5), X() + Y())).has_value());  // a half-space beside a tetrahedron
  EXPECT_FALSE(minkowski::polytopeUnionOf(min(block(lo, hi), -block(nbig, big))).has_value());  // empty
  EXPECT_FALSE(minkowski::polytopeUnionOf(max(block(lo, hi), 0.5 - X() * X())).has_value());    // curved
  // Seven nested differences of slabs: 2^7 terms, past the limit.
  Expr many = block(lo, hi);
  for (int k = 0; k < 7; ++k) many = min(many, max(X() - 0.1 * k, -0.05 * k - Y()));
  EXPECT_FALSE(minkowski::polytopeUnionOf(many).has_value());
  // Two disjoint boxes: a union of two pieces.
  const double lo2[3] = {3, 3, 3}, hi2[3] = {4, 4, 4};
  auto two = minkowski::polytopeUnionOf(max(block(lo, hi), block(lo2, hi2)));
  ASSERT_TRUE(two.has_value());
  EXPECT_EQ(two->pieces, 2u);
}

// The L-slab read from inside: its complement is the outside of block 1 (six half-spaces) and
// block 2, and the distance to them is exact inside the slab, including near the notch's inner
// edge, where the nearest point of the complement is block 2's edge, not a plane.
TEST(PolytopeUnion, ComplementFormIsTheExactDistanceInside) {
  const double lo1[3] = {-1, -1, -0.25}, hi1[3] = {1, 1, 0.25};
  const double lo2[3] = {-0.2, -0.2, -1}, hi2[3] = {1.3, 1.3, 1};
  const Expr slab = min(block(lo1, hi1), -block(lo2, hi2));
  auto c = minkowski::polytopeComplementOf(slab);
  ASSERT_TRUE(c.has_value());
  EXPECT_TRUE(c->exactInside);
  EXPECT_EQ(c->pieces, 7u);
  EXPECT_EQ(c->boxes, 7u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-1.2, 1.2);
  int inside = 0;
  for (int i = 0; i < 4000; ++i) {
    const double p[3] = {coord(rng), coord(rng), coord(rng)};
    const double f = eval(c->field, p[0], p[1], p[2]), original = eval(slab, p[0], p[1], p[2]);
    if (std::abs(original) > 1e-9) EXPECT_EQ(f > 0, original > 0) << p[0] << " " << p[1] << " " << p[2];
    if (!(original > 0)) continue;
    ++inside;
    double d = boxOutsideDistance(p, lo2, hi2);
    for (int a = 0; a < 3; ++a) d = std::min({d, p[a] - lo1[a], hi1[a] - p[a]});
    EXPECT_NEAR(f, d, 1e-12) << p[0] << " " << p[1] << " " << p[2];
  }
  EXPECT_GT(inside, 300);
  EXPECT_NEAR(eval(c->field, -0.3, -0.3, 0), std::sqrt(0.02), 1e-12);  // the notch's edge
  // General planes: a tetrahedron's complement is four half-spaces, each clipped far away; the
  // distance inside is its nearest face's, as the polytope's own exact distance says.
  auto t = minkowski::polytopeComplementOf(tetrahedron(0.5));
  auto own = minkowski::convexPolytopeOf(tetrahedron(0.5));
  ASSERT_TRUE(t.has_value() && own.has_value());
  EXPECT_EQ(t->pieces, 4u);
  EXPECT_EQ(t->boxes, 0u);
  std::uniform_real_distribution<double> small(-0.4, 0.4);
  for (int i = 0; i < 500; ++i) {
    const double x = small(rng), y = small(rng), z = small(rng);
    const double want = eval(own->field, x, y, z);
    if (want > 0) EXPECT_NEAR(eval(t->field, x, y, z), want, 1e-9) << x << " " << y << " " << z;
  }
  // A solid that is all of space has an empty complement: refused.
  EXPECT_FALSE(minkowski::polytopeComplementOf(Expr(1.0) + 0.0 * X()).has_value());
}

// L-slab ⊕ ball: the offset of the union's distance (Roerdink eq. 1: the sum distributes over
// the union); L-slab ⊖ ball: the inward offset of its complement's distance; reported as such.
TEST(PolytopeUnion, SumAndErosionWithABallTakeTheOffsetPath) {
  const double lo1[3] = {-1, -1, -0.25}, hi1[3] = {1, 1, 0.25};
  const double lo2[3] = {-0.2, -0.2, -1}, hi2[3] = {1.3, 1.3, 1};
  const Expr slab = min(block(lo1, hi1), -block(lo2, hi2));
  const double r = 0.3;
  const Expr ball = registeredBall(r);
  Expr sum;
  ASSERT_TRUE(minkowski::distanceBallSum(slab, ball, 3, &sum));
  EXPECT_NEAR(eval(sum, 0.3, 0.4, 0), r - 0.5, 1e-12);  // in the notch, 0.5 from its face x = -0.2
  EXPECT_NEAR(eval(sum, -1.1, 0.5, 0), r - 0.1, 1e-12);
  EXPECT_NEAR(eval(sum, 0.5, -0.5, 0.5), r - 0.25, 1e-12);
  const auto described = minkowski::describeExact(sum);
  ASSERT_FALSE(described.empty());
  EXPECT_NE(described[0].find("union of 2 convex pieces"), std::string::npos) << described[0];
  Expr eroded;
  ASSERT_TRUE(minkowski::distanceBallDifference(slab, ball, 3, &eroded));
  EXPECT_NEAR(eval(eroded, -0.6, 0.5, 0), 0.25 - r, 1e-12);              // the slab's faces z = +-0.25
  EXPECT_NEAR(eval(eroded, -0.3, -0.3, 0), std::sqrt(0.02) - r, 1e-12);  // the notch's edge
  const auto erodedText = minkowski::describeExact(eroded);
  ASSERT_FALSE(erodedText.empty());
  EXPECT_NE(erodedText[0].find("complement of a union of 7 convex pieces"), std::string::npos) << erodedText[0];
}

// The closed-form distance (min, max, sqrt over the facets and edges) against the boundary
// mesh's exact distance at random points inside and outside, for polytopes whose nearest
// features are faces, edges and vertices of every kind: the tetrahedron, a box cut by a slanted
// plane (pentagons), a thin wedge (acute facet angles: the in-facet term's factor K matters) and
// 14 random planes tangent to an ellipsoid.
TEST(ConvexPolytope, ClosedFormDistanceIsTheBoundaryMeshDistance) {
  std::vector<Expr> shapes = {
      tetrahedron(0.5),
      min(min(min(0.5 - X(), 0.5 + X()), min(0.4 - Y(), 0.4 + Y())),
          min(min(0.3 - Z(), 0.3 + Z()), 0.6 - X() - Y() - Z())),
      // a wedge: facets of angle 2 atan(0.1) at the apex x = -1, closed at x = 1
      min(min(min(Y() + 0.1 * X() + 0.1, 0.1 * X() - Y() + 0.1), 1.0 - X()), min(0.5 - Z(), 0.5 + Z()))};
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  std::optional<Expr> random;
  for (int i = 0; i < 14; ++i) {
    double n[3] = {g(rng), g(rng), g(rng)};
    const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    // tangent to the ellipsoid with semi-axes (0.8, 0.5, 0.4) along the unit normal n / l
    const double h = std::sqrt(0.64 * n[0] * n[0] + 0.25 * n[1] * n[1] + 0.16 * n[2] * n[2]) / l;
    const Expr plane = h - (n[0] * X() + n[1] * Y() + n[2] * Z()) / l;
    random = random ? min(*random, plane) : plane;
  }
  shapes.push_back(*random);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  for (size_t s = 0; s < shapes.size(); ++s) {
    auto p = minkowski::convexPolytopeOf(shapes[s]);
    ASSERT_TRUE(p.has_value()) << s;
    ASSERT_NE(p->field.op(), Op::Field) << s;  // the closed form, not the mesh node
    TapePtr closed = Tape::compile(p->field, 3), mesh = Tape::compile(p->mesh, 3);
    PointEvaluator pe;
    int inside = 0;
    for (int i = 0; i < 4000; ++i) {
      const double x[3] = {u(rng), u(rng), u(rng)};
      const double a = pe.eval(*closed, x), b = pe.eval(*mesh, x);
      EXPECT_NEAR(a, b, 1e-12) << s << ": " << x[0] << " " << x[1] << " " << x[2];
      inside += b > 0;
    }
    EXPECT_GT(inside, 20) << s;
    // and is registered as an exact distance
    auto t = minkowski::lookupExact(p->field);
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->kind, minkowski::ExactTerm::Kind::Distance);
  }
}
