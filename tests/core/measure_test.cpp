// Certified mass properties (frep/measure/mass_properties.h) against closed forms: every bound
// must hold the exact value, and volume and area bounds must be at most 0.5 % wide at the
// default tolerance.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "frep/extremum/extremum.h"
#include "frep/measure/mass_properties.h"
#include "frep/minkowski_algebra/basic_set.h"
#include "frep/minkowski_algebra/reduction.h"
#include "frep/evaluators/eval.h"
#include "frep/primitives/ops.h"
#include "frep/primitives/primitives.h"

namespace frep {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Exact {
  double volume = 0, area = 0;
  bool hasCentroid = false;
  double centroid[3] = {0, 0, 0};
  bool hasInertia = false;
  double inertia[9] = {};  // about the centroid
};

MassProperties measure(const Expr& f, double b, const MeasureOptions& o = {}) {
  const Interval box[3] = {{-b, b}, {-b, b}, {-b, b}};
  return measureMassProperties(f, box, o);
}

void expectHolds(const char* what, const MeasureBound& m, double exact, double maxRelWidth) {
  EXPECT_LE(m.lower, exact) << what;
  EXPECT_GE(m.upper, exact) << what;
  EXPECT_LE(m.width(), maxRelWidth * std::fabs(exact)) << what << ": [" << m.lower << ", " << m.upper << "]";
}

MassProperties check(const char* name, const Expr& f, double b, const Exact& e) {
  const auto t0 = std::chrono::steady_clock::now();
  MassProperties m = measure(f, b);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%-16s volume [%.9g, %.9g] exact %.9g width %.3f%%  area [%.9g, %.9g] exact %.9g width %.3f%%  "
              "%llu boundary leaves (%llu first order), %d rounds, depth %d, %.2f s (%s)\n",
              name, m.volume.lower, m.volume.upper, e.volume, 100 * m.volume.width() / e.volume, m.area.lower,
              m.area.upper, e.area, 100 * m.area.width() / e.area, (unsigned long long)m.boundaryCells,
              (unsigned long long)m.firstOrderCells, m.rounds, m.depth, s, m.stopReason.c_str());
  expectHolds("volume", m.volume, e.volume, 0.005);
  expectHolds("area", m.area, e.area, 0.005);
  EXPECT_TRUE(m.toleranceReached) << m.stopReason;
  EXPECT_EQ(m.cutFaces, 0u);
  if (e.hasCentroid)
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(m.centroid[size_t(i)].lower, e.centroid[i]) << name << " centroid " << i;
      EXPECT_GE(m.centroid[size_t(i)].upper, e.centroid[i]) << name << " centroid " << i;
      EXPECT_LE(m.centroid[size_t(i)].width(), 0.005 * std::cbrt(e.volume)) << name << " centroid " << i;
    }
  if (e.hasInertia) {
    double scale = 0;
    for (double v : e.inertia) scale = std::max(scale, std::fabs(v));
    for (int k = 0; k < 9; ++k) {
      EXPECT_LE(m.inertia[size_t(k)].lower, e.inertia[k]) << name << " inertia " << k;
      EXPECT_GE(m.inertia[size_t(k)].upper, e.inertia[k]) << name << " inertia " << k;
      EXPECT_LE(m.inertia[size_t(k)].width(), 0.02 * scale) << name << " inertia " << k;
    }
  }
  return m;
}

// The inertia tensor about the origin from the one about the centroid (parallel axes).
void toOrigin(const Exact& e, double out[9]) {
  const double* c = e.centroid;
  const double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i * 3 + j] = e.inertia[i * 3 + j] + e.volume * ((i == j ? c2 : 0.0) - c[i] * c[j]);
}

Exact boxExact(double lx, double ly, double lz, const double c[3]) {
  Exact e;
  e.volume = lx * ly * lz;
  e.area = 2 * (lx * ly + ly * lz + lz * lx);
  e.hasCentroid = e.hasInertia = true;
  for (int i = 0; i < 3; ++i) e.centroid[i] = c[i];
  e.inertia[0] = e.volume * (ly * ly + lz * lz) / 12;
  e.inertia[4] = e.volume * (lz * lz + lx * lx) / 12;
  e.inertia[8] = e.volume * (lx * lx + ly * ly) / 12;
  return e;
}

TEST(Measure, OffCentreBox) {
  // min of the six half-spaces (block with a = 1), faces not on the octree's planes.
  const double c[3] = {0.13, -0.21, 0.37};
  const Expr f = block({Expr(c[0]), Expr(c[1]), Expr(c[2])}, {Expr(0.45), Expr(0.35), Expr(0.6)});
  const Exact e = boxExact(0.9, 0.7, 1.2, c);
  MassProperties m = check("box", f, 1.5, e);
  double io[9];
  toOrigin(e, io);
  for (int k = 0; k < 9; ++k) {
    EXPECT_LE(m.inertiaOrigin[size_t(k)].lower, io[k]) << k;
    EXPECT_GE(m.inertiaOrigin[size_t(k)].upper, io[k]) << k;
  }
}

TEST(Measure, ExactDistanceBox) {
  // The basic set's block: minus the exact signed distance, whose formula kinks on every face
  // (|max(d, 0)| + min(max d_i, 0)); measureForm measures it as max d_i, which has its sign.
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Block;
  s.size = {0.8, 0.6, 1.1};
  s.pos = {-0.31, 0.12, -0.43};
  const Expr f = minkowski::unionExpr(minkowski::reduce(minkowski::sumOf(s)));
  const double c[3] = {-0.31 + 0.4, 0.12 + 0.3, -0.43 + 0.55};
  check("distance box", f, 1.5, boxExact(0.8, 0.6, 1.1, c));
}

TEST(Measure, RotatedBox) {
  const double c0[3] = {0, 0, 0};
  const Expr f = rotateX(rotateZ(block({Expr(0.0), Expr(0.0), Expr(0.0)}, {Expr(0.5), Expr(0.3), Expr(0.4)}), 0.5), 0.3);
  Exact e = boxExact(1.0, 0.6, 0.8, c0);
  e.hasInertia = false;  // rotated: checked through its trace, which rotation keeps
  MassProperties m = check("rotated box", f, 1.5, e);
  const double trace = e.volume * 2 * (1.0 + 0.36 + 0.64) / 12;
  const MeasureBound t = {m.inertia[0].lower + m.inertia[4].lower + m.inertia[8].lower,
                          m.inertia[0].upper + m.inertia[4].upper + m.inertia[8].upper};
  EXPECT_LE(t.lower, trace);
  EXPECT_GE(t.upper, trace);
}

TEST(Measure, OffCentreBall) {
  Exact e;
  const double r = 0.8;
  e.volume = 4.0 / 3.0 * kPi * r * r * r;
  e.area = 4 * kPi * r * r;
  e.hasCentroid = e.hasInertia = true;
  e.centroid[0] = 0.3, e.centroid[1] = -0.2, e.centroid[2] = 0.15;
  for (int i = 0; i < 3; ++i) e.inertia[i * 4] = 0.4 * e.volume * r * r;
  MassProperties m = check("ball", sphere({Expr(0.3), Expr(-0.2), Expr(0.15)}, r), 1.5, e);
  double io[9];
  toOrigin(e, io);
  for (int k = 0; k < 9; ++k) {
    EXPECT_LE(m.inertiaOrigin[size_t(k)].lower, io[k]) << k;
    EXPECT_GE(m.inertiaOrigin[size_t(k)].upper, io[k]) << k;
  }
}

TEST(Measure, Torus) {
  const double R = 1.0, r = 0.3;
  Exact e;
  e.volume = 2 * kPi * kPi * R * r * r;
  e.area = 4 * kPi * kPi * R * r;
  check("torus", torusZ({Expr(0.0), Expr(0.0), Expr(0.0)}, R, r), 1.5, e);
}

TEST(Measure, Cylinder) {
  const double r = 0.5, H = 1.4;
  const Expr f = min(cylinderZ({Expr(0.0), Expr(0.0), Expr(0.0)}, r), 0.7 - abs(Expr::x(2) - 0.1));
  Exact e;
  e.volume = kPi * r * r * H;
  e.area = 2 * kPi * r * H + 2 * kPi * r * r;
  e.hasCentroid = true;
  e.centroid[2] = 0.1;
  check("cylinder", f, 1.5, e);
}

TEST(Measure, MinkowskiBoxPlusBallBySteiner) {
  // a x b x c block ⊕ ball r, exact Minkowski algebra (no search): Steiner's formula.
  const double a = 0.6, b = 0.4, c = 0.8, r = 0.25;
  minkowski::Shape blk, ball;
  blk.kind = minkowski::ShapeKind::Block;
  blk.size = {a, b, c};
  blk.pos = {-0.3, -0.2, -0.4};
  ball.kind = minkowski::ShapeKind::Sphere;
  ball.size = {r, 0, 0};
  minkowski::Sum s = minkowski::sumOf(blk);
  ASSERT_TRUE(s.add(ball));
  const Expr f = minkowski::unionExpr(minkowski::reduce(s));
  Exact e;
  e.volume = a * b * c + 2 * (a * b + b * c + c * a) * r + kPi * (a + b + c) * r * r + 4.0 / 3.0 * kPi * r * r * r;
  e.area = 2 * (a * b + b * c + c * a) + 2 * kPi * (a + b + c) * r + 4 * kPi * r * r;
  e.hasCentroid = true;
  check("box+ball", f, 1.5, e);
}

TEST(Measure, ProjectionOf4DBall) {
  // max over x3 of (r^2 - |X - c|^2 - x3^2): the 3D ball of radius r (an extremum node).
  const double r = 0.7;
  const Expr f4 = ball({Expr(0.1), Expr(0.0), Expr(-0.1), Expr(0.2)}, r);
  Bounds bx;
  bx.lo = {0.2 - r};
  bx.hi = {0.2 + r};
  const Expr f = project(f4, 4, {3}, bx);
  Exact e;
  e.volume = 4.0 / 3.0 * kPi * r * r * r;
  e.area = 4 * kPi * r * r;
  e.hasCentroid = true;
  e.centroid[0] = 0.1, e.centroid[2] = -0.1;
  check("4D ball proj.", f, 1.5, e);
}

TEST(Measure, RFunctionBox) {
  // HyperFun-style block: R-conjunctions (a = 0) of the slabs, smooth across the faces' edges
  // everywhere but on the solid; measureForm measures it through min, which has its sign.
  const double c[3] = {0.13, -0.21, 0.37};
  const Expr f = block({Expr(c[0]), Expr(c[1]), Expr(c[2])}, {Expr(0.45), Expr(0.35), Expr(0.6)}, Expr(0.0));
  check("R-function box", f, 1.5, boxExact(0.9, 0.7, 1.2, c));
}

TEST(Measure, HyperFunSlabBlock) {
  // hfBlock's form: R-conjunctions of slabs (x - v)(v + d - x), measured as min of half-spaces.
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr f = rIntersection(rIntersection((x + 0.3) * (0.5 - x), (y + 0.2) * (0.6 - y)), (z - 0.1) * (0.4 - z));
  const double c[3] = {0.1, 0.2, 0.25};
  check("hfBlock form", f, 1.5, boxExact(0.8, 0.8, 0.3, c));
}

TEST(Measure, MeasureFormHasTheSignOfTheField) {
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Block;
  s.size = {0.8, 0.6, 1.1};
  s.pos = {-0.31, 0.12, -0.43};
  const Expr box = minkowski::unionExpr(minkowski::reduce(minkowski::sumOf(s)));
  const Expr rblock = block({Expr(0.1), Expr(0.0), Expr(0.0)}, {Expr(0.5), Expr(0.4), Expr(0.3)}, Expr(0.0));
  const Expr blend = rUnion(sphere({Expr(0.2), Expr(0.0), Expr(0.0)}, 0.5), 2.0 * -rblock, 0.3);
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr slabs = rIntersection(rIntersection((x + 0.3) * (0.5 - x), (y + 0.2) * (0.6 - y)), (z - 0.1) * (0.4 - z));
  const Expr notSlabs = (x + 0.3) * (x - 0.5);  // a + b not constant: kept as it is
  EXPECT_TRUE(measureForm(notSlabs).same(notSlabs));
  for (const Expr& f : {box, rblock, blend, slabs}) {
    TapePtr a = Tape::compile(f, 3), b = Tape::compile(measureForm(f), 3);
    PointEvaluator pa, pb;
    uint64_t state = 12345;
    for (int k = 0; k < 20000; ++k) {
      double p[3];
      for (double& v : p) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        v = -1.2 + 2.4 * double(state >> 11) / double(1ull << 53);
      }
      // Grid points too, where the faces are (exact zeros).
      if (k % 4 == 0)
        for (double& v : p) v = std::round(v * 20) / 20;
      const double fa = pa.eval(*a, p), fb = pb.eval(*b, p);
      EXPECT_EQ(fa > 0, fb > 0) << p[0] << " " << p[1] << " " << p[2];
      EXPECT_EQ(fa < 0, fb < 0) << p[0] << " " << p[1] << " " << p[2];
    }
  }
}

TEST(Measure, SolidCutByTheBoxIsMeasuredInsideIt) {
  // Unit ball in a box that keeps z >= 0: half a ball, whose boundary has the flat disc.
  const Interval box[3] = {{-1.5, 1.5}, {-1.5, 1.5}, {0.0, 1.5}};
  MassProperties m = measureMassProperties(Tape::compile(sphere({Expr(0.0), Expr(0.0), Expr(0.0)}, 1.0), 3), box);
  expectHolds("half volume", m.volume, 2.0 / 3.0 * kPi, 0.005);
  expectHolds("half area", m.area, 3 * kPi, 0.005);
  expectHolds("cut area", m.cutArea, kPi, 0.005);
  EXPECT_EQ(m.cutFaces, 1u << 4);  // z-min
  EXPECT_LE(m.centroid[2].lower, 3.0 / 8.0);
  EXPECT_GE(m.centroid[2].upper, 3.0 / 8.0);
}

TEST(Measure, SameNumbersForAnyThreadCount) {
  const Expr f = min(sphere({Expr(0.1), Expr(0.0), Expr(0.0)}, 0.9), 0.5 - abs(Expr::x(2) - 0.05));
  MeasureOptions one, two;
  one.threads = 1;
  two.threads = 2;
  one.tolerance = two.tolerance = 0.02;
  MassProperties a = measure(f, 1.5, one), b = measure(f, 1.5, two);
  EXPECT_EQ(a.volume.lower, b.volume.lower);
  EXPECT_EQ(a.volume.upper, b.volume.upper);
  EXPECT_EQ(a.area.lower, b.area.lower);
  EXPECT_EQ(a.area.upper, b.area.upper);
  for (size_t k = 0; k < 9; ++k) {
    EXPECT_EQ(a.inertia[k].lower, b.inertia[k].lower);
    EXPECT_EQ(a.inertia[k].upper, b.inertia[k].upper);
  }
  EXPECT_EQ(a.boundaryCells, b.boundaryCells);
}

TEST(Measure, TighterToleranceTightensAndStillHolds) {
  MeasureOptions o;
  o.tolerance = 1e-3;
  const double r = 0.8;
  MassProperties m = measure(sphere({Expr(0.0), Expr(0.0), Expr(0.0)}, r), 1.0, o);
  expectHolds("volume", m.volume, 4.0 / 3.0 * kPi * r * r * r, 1e-3);
  expectHolds("area", m.area, 4 * kPi * r * r, 1e-3);
}

TEST(Measure, EmptyAndFullBoxes) {
  MassProperties empty = measure(Expr(-1.0), 1.0);
  EXPECT_EQ(empty.volume.lower, 0.0);
  EXPECT_EQ(empty.volume.upper, 0.0);
  EXPECT_EQ(empty.area.upper, 0.0);
  MassProperties full = measure(Expr(1.0), 1.0);
  expectHolds("full", full.volume, 8.0, 1e-9);
  expectHolds("full area (all cut)", full.area, 24.0, 1e-9);
  EXPECT_EQ(full.cutFaces, 63u);
}

}  // namespace
}  // namespace frep
