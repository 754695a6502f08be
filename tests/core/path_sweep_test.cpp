// Sweeps by translation along a polyline (minkowski_algebra/path_sweep.h): a ball's capsules,
// a box's and a block difference's convex hulls, against the distance to the moving operand
// minimised over the time by golden-section search (the distance to a convex piece moved along
// a segment is convex in the time).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"
#include "frep/minkowski_algebra/path_sweep.h"
#include "frep/minkowski_algebra/registry.h"

using namespace frep;
using minkowski::Vec3;

namespace {

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

double eval(const Expr& e, const Vec3& p) {
  TapePtr t = Tape::compile(e, 3);
  PointEvaluator pe;
  return pe.eval(*t, p.data());
}

Expr block(const Vec3& lo, const Vec3& hi) {
  const Expr c[3] = {X(), Y(), Z()};
  Expr e;
  for (int a = 0; a < 3; ++a) {
    const Expr slab = min(c[a] - lo[size_t(a)], hi[size_t(a)] - c[a]);
    e = a == 0 ? slab : min(e, slab);
  }
  return e;
}

double boxDistance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  double s = 0;
  for (size_t a = 0; a < 3; ++a) {
    const double d = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    s += d * d;
  }
  return std::sqrt(s);
}

// min over t in [0, 1] of dist(p - (a + t (b - a)), box): convex in t, golden-section search.
double sweptBoxDistance(const Vec3& p, const Vec3& lo, const Vec3& hi, const Vec3& a, const Vec3& b) {
  auto at = [&](double t) {
    const Vec3 q{p[0] - a[0] - t * (b[0] - a[0]), p[1] - a[1] - t * (b[1] - a[1]), p[2] - a[2] - t * (b[2] - a[2])};
    return boxDistance(q, lo, hi);
  };
  double l = 0, h = 1;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 200; ++i) {
    const double m1 = h - g * (h - l), m2 = l + g * (h - l);
    if (at(m1) <= at(m2)) h = m2;
    else l = m1;
  }
  return std::min({at(0), at(1), at(0.5 * (l + h))});
}

}  // namespace

TEST(PathSweep, BallAlongAPolylineIsItsCapsules) {
  const double r = 0.25;
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Sphere;
  s.size[0] = r;
  s.pos = {0, 0, 0.5};
  const Expr ball = r * r - X() * X() - Y() * Y() - square(Z() - 0.5);
  minkowski::ExactTerm t;
  t.sum = minkowski::sumOf(s);
  t.pieces = 1;
  minkowski::registerExact(ball, t);
  const std::vector<Vec3> path = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  Expr swept;
  ASSERT_TRUE(minkowski::translationSweep(ball, path, &swept));
  // Points, the ball's centre moved: dist to the polyline through (0, 0, 0.5) ...
  const Vec3 probes[] = {{0.5, 0.1, 0.5}, {0.5, 0.3, 0.5},  {1.2, 0.5, 0.6},
                         {-0.3, 0, 0.5},  {1.2, -0.2, 0.5}, {2, 2, 2}};
  const double want[] = {
      r - 0.1, r - 0.3, r - std::hypot(0.2, 0.1), r - 0.3, r - std::hypot(0.2, 0.2), r - std::sqrt(1 + 1 + 1.5 * 1.5)};
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(eval(swept, probes[i]), want[i], 1e-12) << i;
  const auto described = minkowski::describeExact(swept);
  ASSERT_FALSE(described.empty());
  EXPECT_NE(described[0].find("sweep of ball(r 0.25 at (0, 0, 0.5)) along a path of 3 points"), std::string::npos)
      << described[0];
}

// A box moved along a diagonal: the hull of its two ends, and along two segments the union of
// two hulls; the exact distance outside, the same set everywhere.
TEST(PathSweep, BoxAndBlockDifferenceAlongAPathAreTheirHulls) {
  const Vec3 lo{-0.5, -0.25, -0.1}, hi{0.5, 0.25, 0.1};
  const std::vector<Vec3> path = {{0, 0, 0}, {1, 0.8, 0.3}, {1.5, -0.5, 0.3}};
  Expr swept;
  ASSERT_TRUE(minkowski::translationSweep(block(lo, hi), path, &swept));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 2.2);
  int outside = 0;
  for (int i = 0; i < 1500; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng) * 0.5};
    const double d =
        std::min(sweptBoxDistance(p, lo, hi, path[0], path[1]), sweptBoxDistance(p, lo, hi, path[1], path[2]));
    const double f = eval(swept, p);
    if (d > 1e-9) {
      ++outside;
      EXPECT_NEAR(f, -d, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    } else {
      EXPECT_GE(f, -1e-12) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(outside, 500);
  // An L of two boxes (a block minus a block) along one segment: the union of two hulls.
  const Vec3 lo2{-0.1, -0.1, -1}, hi2{1, 1, 1};
  const Expr ell = min(block(lo, hi), -block(lo2, hi2));
  Expr lswept;
  ASSERT_TRUE(minkowski::translationSweep(ell, {{0, 0, 0}, {0, 0, 1}}, &lswept));
  const Vec3 a{-0.5, -0.25, -0.1}, b{-0.1, 0.25, 0.1}, c{-0.5, -0.25, -0.1}, e{0.5, -0.1, 0.1};
  for (int i = 0; i < 800; ++i) {
    const Vec3 p{u(rng) - 0.5, u(rng) - 0.5, u(rng)};
    const double d =
        std::min(sweptBoxDistance(p, a, b, {0, 0, 0}, {0, 0, 1}), sweptBoxDistance(p, c, e, {0, 0, 0}, {0, 0, 1}));
    if (d > 1e-9) {
      EXPECT_NEAR(eval(lswept, p), -d, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  // A curved operand has no such form.
  Expr none;
  EXPECT_FALSE(minkowski::translationSweep(0.5 - X() * X() - Y() * Y() - Z() * Z(), path, &none));
}
