// Operation library: exact values and sign rules of R-functions, blending, offsets, Cartesian
// product, mapping round trips and metamorphosis.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/primitives/ops.h"
#include "frep/primitives/primitives.h"

using namespace frep;

namespace {

// A compiled field evaluated at points given as vectors.
struct Field {
  explicit Field(const Expr& e, uint32_t dims = 3) : tape(Tape::compile(e, dims)) {}
  double operator()(std::vector<double> p) {
    p.resize(tape->numVars(), 0.0);
    return pe.eval(*tape, p.data());
  }
  TapePtr tape;
  PointEvaluator pe;
};

int sgn(double v) { return (v > 0) - (v < 0); }

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

// Non-symmetric test field: any mapping error shows up in its value.
Expr probe() { return X + 2.0 * square(Y) - 3.0 * Z + X * Y * Z + sin(Z); }

std::vector<std::vector<double>> randomPoints(int n, double lo, double hi, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<std::vector<double>> pts;
  for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  return pts;
}

// f(map(inverse(X))) == f(X) at every point.
void expectRoundTrip(const Mapping& m, const std::vector<std::vector<double>>& pts) {
  Expr f = probe();
  Field direct(f), there(remap(remap(f, m.forward), m.inverse));
  for (auto& p : pts) EXPECT_NEAR(there(p), direct(p), 1e-9) << p[0] << " " << p[1] << " " << p[2];
}

}  // namespace

TEST(RFunctions, SignRulesOnRandomSamples) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<std::pair<double, double>> samples = {{0, 0}, {0, 1}, {1, 0}, {0, -1}, {-1, 0},
                                                    {1, 1}, {-1, -1}, {1, -1}, {0.5, 0.5}};
  for (int i = 0; i < 5000; ++i) samples.push_back({u(rng), u(rng)});
  for (double a : {1.0, 0.5, 0.0, -0.5, -0.9}) {
    Field uni(rUnion(X, Y, a), 2), inter(rIntersection(X, Y, a), 2), sub(rSubtraction(X, Y, a), 2);
    for (auto [f1, f2] : samples) {
      EXPECT_EQ(sgn(uni({f1, f2})), sgn(std::max(f1, f2))) << a << " " << f1 << " " << f2;
      EXPECT_EQ(sgn(inter({f1, f2})), sgn(std::min(f1, f2))) << a << " " << f1 << " " << f2;
      EXPECT_EQ(sgn(sub({f1, f2})), sgn(std::min(f1, -f2))) << a << " " << f1 << " " << f2;
    }
  }
  for (double m : {1.0, 2.0, 3.0, 0.5}) {
    Field uni(rUnionSmooth(X, Y, m), 2), inter(rIntersectionSmooth(X, Y, m), 2);
    for (auto [f1, f2] : samples) {
      EXPECT_EQ(sgn(uni({f1, f2})), sgn(std::max(f1, f2))) << m << " " << f1 << " " << f2;
      EXPECT_EQ(sgn(inter({f1, f2})), sgn(std::min(f1, f2))) << m << " " << f1 << " " << f2;
    }
  }
}

TEST(RFunctions, ExactValues) {
  // a = 0: 3 + 4 ± 5. Constants fold; the same through a tape.
  EXPECT_EQ(rUnion(3.0, 4.0, 0.0).constValue(), 12.0);
  EXPECT_EQ(rIntersection(3.0, 4.0, 0.0).constValue(), 2.0);
  Field uni(rUnion(X, Y), 2), inter(rIntersection(X, Y), 2), sub(rSubtraction(X, Y), 2);
  EXPECT_EQ(uni({3, 4}), 12.0);
  EXPECT_EQ(inter({3, 4}), 2.0);
  EXPECT_EQ(sub({3, 4}), -6.0);  // 3 + (-4) - 5
  EXPECT_EQ(rNegation(X).op(), Op::Neg);
  // a = 0.5: (7 ± sqrt(9 + 16 - 12)) / 1.5.
  Field u5(rUnion(X, Y, 0.5), 2), i5(rIntersection(X, Y, 0.5), 2);
  EXPECT_DOUBLE_EQ(u5({3, 4}), (7 + std::sqrt(13.0)) / 1.5);
  EXPECT_DOUBLE_EQ(i5({3, 4}), (7 - std::sqrt(13.0)) / 1.5);
  // a = 1: exactly max / min.
  Field u1(rUnion(X, Y, 1.0), 2), i1(rIntersection(X, Y, 1.0), 2);
  EXPECT_EQ(u1({3, 4}), 4.0);
  EXPECT_EQ(i1({3, 4}), 3.0);
  // Smooth R_0^m: (7 ± 5) · 25^(m/2).
  EXPECT_EQ(Field(rUnionSmooth(X, Y, 1), 2)({3, 4}), 60.0);
  EXPECT_EQ(Field(rUnionSmooth(X, Y, 2), 2)({3, 4}), 300.0);
  EXPECT_EQ(Field(rIntersectionSmooth(X, Y, 2), 2)({3, 4}), 50.0);
  EXPECT_EQ(Field(rIntersectionSmooth(X, Y, 3), 2)({3, 4}), 250.0);
  EXPECT_DOUBLE_EQ(Field(rUnionSmooth(X, Y, 0.5), 2)({3, 4}), 12.0 * std::sqrt(5.0));
}

TEST(RFunctions, AOneBuildsExtremumNodesThatIntervalsPrune) {
  EXPECT_EQ(rUnion(X, Y, 1.0).op(), Op::Max);
  EXPECT_EQ(rIntersection(X, Y, 1.0).op(), Op::Min);
  TapePtr t = Tape::compile(rUnion(X, square(Y) + Y, 1.0), 2);
  EXPECT_EQ(t->numChoices(), 1u);
  IntervalEvaluator ie;
  Interval box[2] = {{2, 3}, {0, 0.5}};  // y² + y <= 0.75 < x: the max is decided
  Interval r = ie.eval(*t, box);
  EXPECT_GE(r.lo, 2.0 - 1e-12);
  EXPECT_LE(r.hi, 3.0 + 1e-12);
  TapePtr p = ie.pruned(t);
  EXPECT_LT(p->size(), t->size());
  PointEvaluator pe;
  double pt[2] = {2.5, 0.25};
  EXPECT_EQ(pe.eval(*p, pt), 2.5);
}

TEST(RFunctions, SmoothFormHasZeroGradientAtDoubleZero) {
  // C^1 at f1 = f2 = 0 (the a = 0 system is not differentiable there).
  for (uint32_t v : {0u, 1u}) {
    Field d(derivative(rUnionSmooth(X, Y, 1), v), 2);
    EXPECT_EQ(d({0, 0}), 0.0);
  }
}

TEST(RFunctions, RejectsBadParameters) {
  for (double a : {-1.0, -2.0, 1.5, std::nan("")})
    EXPECT_THROW(rUnion(X, Y, a), std::invalid_argument) << a;
  EXPECT_THROW(rIntersection(X, Y, -1.0), std::invalid_argument);
  EXPECT_NO_THROW(rUnion(X, Y, -0.99));
  EXPECT_NO_THROW(rUnion(X, Y, Expr::param(0)));  // a field: checked by whoever binds it
  EXPECT_THROW(rUnionSmooth(X, Y, -1), std::invalid_argument);
}

TEST(Blending, AddsDisplacementToTheRFunction) {
  Field bu(blendUnion(X, Y, 1.0, 1.0, 2.0), 2), bi(blendIntersection(X, Y, 1.0, 1.0, 2.0), 2);
  EXPECT_DOUBLE_EQ(bu({3, 4}), 12.0 + 1.0 / 14.0);
  EXPECT_DOUBLE_EQ(bi({3, 4}), 2.0 + 1.0 / 14.0);
  EXPECT_EQ(bu({0, 0}), 1.0);  // on the common edge the displacement is a0
  Field bm(blendIntersection(X, Y, -0.5, 1.0, 1.0, 1.0), 2);
  EXPECT_EQ(bm({0, 0}), -0.5);
  EXPECT_THROW(blendUnion(X, Y, 1.0, 0.0, 1.0), std::invalid_argument);
}

TEST(Offsets, ConstantOffset) {
  Field f(offsetConst(sphere({0.0, 0.0, 0.0}, 1.0), 0.5));
  EXPECT_EQ(f({0, 0, 0}), 1.5);
}

TEST(Offsets, NormalOffsetOfUnitSphereMovesItsSurfaceByD) {
  for (double d : {0.5, -0.3}) {
    Field f(offsetNormal(sphere({0.0, 0.0, 0.0}, 1.0), d));
    // f(X + D·n) = 1 − (|X| − D)² for |X| > 0, zero on |X| = 1 + D.
    for (auto& p : randomPoints(500, -2.0, 2.0, 11)) {
      double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      EXPECT_NEAR(f(p), 1.0 - (r - d) * (r - d), 1e-12);
      double k = (1.0 + d) / r;
      EXPECT_NEAR(f({p[0] * k, p[1] * k, p[2] * k}), 0.0, 1e-12);
    }
    EXPECT_EQ(f({0, 0, 0}), 1.0);  // no gradient at the centre: the point stays
  }
}

TEST(CartesianProduct, DiscTimesSegmentIsACylinder) {
  Expr segment = rIntersection(X - 0.0, 1.0 - X, 1.0);  // [0, 1] on its own x0
  Expr f = product(disc({0.0, 0.0}, 1.0), 2, segment, 1.0);
  EXPECT_EQ(numVars(f), 3u);
  Field c(f);
  EXPECT_EQ(c({0, 0, 0.5}), 0.5);
  EXPECT_EQ(c({0, 0, 0.25}), 0.25);
  EXPECT_EQ(c({2, 0, 0.5}), -3.0);
  EXPECT_EQ(c({0.5, 0, 2}), -1.0);
  Field c0(product(disc({0.0, 0.0}, 1.0), 2, segment, 0.0));
  for (auto& p : randomPoints(500, -1.5, 1.5, 3))
    EXPECT_EQ(sgn(c0(p)), sgn(c(p))) << p[0] << " " << p[1] << " " << p[2];
  EXPECT_THROW(product(Z, 2, X), std::invalid_argument);
}

TEST(Mappings, RoundTrips) {
  auto pts = randomPoints(200, -2.0, 2.0, 5);
  std::vector<Mapping> maps = {
      affineMap({2, 1, 0, 0, 1, 0.5, 1, 0, 3}, {1, -2, 0.5}),
      translateMap({1.0, -2.0, 3.0}),
      scaleMap({2.0, 0.5, -3.0}),
      rotateMap(Axis::X, 0.7),
      rotateMap(Axis::Y, -1.2),
      rotateMap(Axis::Z, 2.5),
      twistMap(Axis::Z, -1.0, 1.0, 0.3, 2.0),
      twistRateMap(Axis::X, 1.1),
      taperMap(Axis::Y, -1.0, 1.0, 0.5, 2.0),
      rotateMap(Axis::Z, 0.4).then(translateMap({1.0, 0.0, 2.0})),
  };
  for (auto& m : maps) {
    expectRoundTrip(m, pts);
    expectRoundTrip(m.inverted(), pts);
  }
  // Bend and the cylindrical map are bijective on a domain only.
  auto bendPts = randomPoints(200, -1.5, 1.5, 9);
  for (double r : {2.0, -2.0}) {
    expectRoundTrip(bendMap(Axis::X, Axis::Y, r), bendPts);
    expectRoundTrip(bendMap(Axis::X, Axis::Y, r).inverted(), bendPts);
  }
  expectRoundTrip(cylindricalToCartesianMap(), pts);  // Cartesian -> (r, phi, z) -> back
  auto polar = randomPoints(200, 0.1, 3.0, 13);        // r > 0, phi in (0, 3) ⊂ (−π, π)
  expectRoundTrip(cylindricalToCartesianMap().inverted(), polar);
}

TEST(Mappings, AffineMatchesItsDefinition) {
  std::vector<double> b = {2, 1, 0, 0, 1, 0.5, 1, 0, 3}, c = {1, -2, 0.5};
  Field f(affine(probe(), b, c)), g(probe());
  for (auto& p : randomPoints(50, -2.0, 2.0, 17)) {
    std::vector<double> q(3, 0.0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) q[i] += b[i * 3 + j] * (p[j] - c[j]);
    EXPECT_NEAR(f(p), g(q), 1e-12);
  }
  EXPECT_THROW(affineMap({1, 2, 2, 4}, {0, 0}), std::invalid_argument);
}

TEST(Mappings, MoveSolidsWhereExpected) {
  Expr s = sphere({2.0, 0.0, 0.0}, 1.0);
  EXPECT_EQ(Field(translate(s, {1.0, 2.0, 3.0}))({3, 2, 3}), 1.0);
  EXPECT_NEAR(Field(rotateZ(s, M_PI / 2))({0, 2, 0}), 1.0, 1e-15);
  EXPECT_NEAR(Field(rotateX(sphere({0.0, 2.0, 0.0}, 1.0), M_PI / 2))({0, 0, 2}), 1.0, 1e-15);
  EXPECT_NEAR(Field(rotateY(sphere({0.0, 0.0, 2.0}, 1.0), M_PI / 2))({2, 0, 0}), 1.0, 1e-15);
  EXPECT_EQ(Field(scale(s, {2.0, 2.0, 2.0}))({4, 0, 0}), 1.0);
  // Twisting an off-axis cylinder by a quarter turn per unit: at z = 1 its axis is at (0, 2).
  Expr cyl = cylinderZ({2.0, 0.0, 0.0}, 0.5);
  EXPECT_NEAR(Field(twistRate(cyl, Axis::Z, M_PI / 2))({0, 2, 1}), 0.25, 1e-14);
  EXPECT_NEAR(Field(twist(cyl, Axis::Z, 0.0, 1.0, 0.0, M_PI))({-2, 0, 1}), 0.25, 1e-14);
  // Taper from scale 1 at z = 0 to 2 at z = 1 (clamped beyond): the radius follows.
  Field t(taper(cylinderZ({0.0, 0.0, 0.0}, 1.0), Axis::Z, 0.0, 1.0, 1.0, 2.0));
  EXPECT_EQ(t({1.5, 0, 0.5}), 0.0);
  EXPECT_EQ(t({0, 2, 1}), 0.0);
  EXPECT_EQ(t({0, 2, 5}), 0.0);
  EXPECT_EQ(t({1, 0, -3}), 0.0);
  EXPECT_THROW(taperMap(Axis::Z, 0.0, 1.0, 1.0, -1.0), std::invalid_argument);
  // Bending the bar |y| <= 0.1 along x around the circle of radius 2 centred at (0, 2).
  Field bent(bend(0.01 - square(Y), Axis::X, Axis::Y, 2.0));
  EXPECT_NEAR(bent({2, 2, 0}), 0.01, 1e-14);
  EXPECT_NEAR(bent({0, 4, 0}), 0.01, 1e-14);
  EXPECT_EQ(bent({0, 2, 0}), 0.01 - 4.0);
  // A solid given in (r, phi, z): r <= 1 and phi >= 0 is the upper half of a cylinder.
  Field cyl2(cylindricalToCartesian(rIntersection(1.0 - X, Y, 1.0)));
  EXPECT_NEAR(cyl2({0.6, 0.8, 5}), 0.0, 1e-15);
  EXPECT_GT(cyl2({-0.5, 1e-3, 0}), 0.0);
  EXPECT_LT(cyl2({-0.5, -1e-3, 0}), 0.0);
  // And back: the unit sphere in (r, phi, z) space is r² + z² <= 1 for every phi.
  Field back(cartesianToCylindrical(sphere({0.0, 0.0, 0.0}, 1.0)));
  EXPECT_NEAR(back({0.6, 2.0, 0.8}), 0.0, 1e-15);
  EXPECT_NEAR(back({0.0, -1.0, 0.5}), 0.75, 1e-15);
}

TEST(Metamorphosis, EndsEqualTheOperands) {
  Expr f1 = sphere({0.0, 0.0, 0.0}, 1.0), f2 = block({1.0, 0.0, 0.0}, {0.5, 0.5, 0.5});
  Field a(f1), b(f2), m0(morph(f1, f2, 0.0)), m1(morph(f1, f2, 1.0));
  Field l1(morphLinear(f1, f2, 1.0)), l0(morphLinear(f1, f2, 0.0));
  Field along(morphAlongAxis(f1, f2, 3, -1.0, 1.0), 4);
  EXPECT_EQ(numVars(morphAlongAxis(f1, f2, 3, -1.0, 1.0)), 4u);
  for (auto& p : randomPoints(200, -2.0, 2.0, 21)) {
    EXPECT_EQ(m0(p), a(p));
    EXPECT_EQ(m1(p), b(p));
    EXPECT_EQ(l1(p), a(p));
    EXPECT_EQ(l0(p), b(p));
    for (double t : {-5.0, -1.0}) EXPECT_EQ(along({p[0], p[1], p[2], t}), a(p));
    for (double t : {1.0, 7.0}) EXPECT_EQ(along({p[0], p[1], p[2], t}), b(p));
    EXPECT_DOUBLE_EQ(along({p[0], p[1], p[2], 0.0}), 0.5 * (a(p) + b(p)));
  }
  EXPECT_THROW(morphAlongAxis(f1, f2, 2, 0.0, 1.0), std::invalid_argument);
}
