// Volume splines (Pasko-Survey, reconstruction from scattered points): interpolation at every
// centre, agreement of the evaluators, sound bounds, the gradient, errors, and the sphere
// reconstructed from 2,000 surface points.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/meshing/mesh.h"
#include "frep/primitives/volume_spline.h"
#include "mesh_checks.h"

namespace frep {
namespace {

double smooth(const Point3& p) { return std::sin(2.0 * p[0]) + p[1] * p[2] - 0.5 * p[2] * p[2]; }

std::vector<Point3> randomPoints(size_t n, unsigned seed, double lo = -1.0, double hi = 2.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<Point3> p(n);
  for (auto& q : p) q = {u(rng), u(rng), 0.5 * u(rng)};
  return p;
}

// Points on the unit sphere (Fibonacci lattice) with their outward normals.
void spherePoints(size_t n, double radius, std::vector<Point3>& p, std::vector<Point3>& nrm) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (size_t i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (double(i) + 0.5) / double(n), r = std::sqrt(1.0 - z * z), t = golden * double(i);
    nrm.push_back({r * std::cos(t), r * std::sin(t), z});
    p.push_back({radius * nrm.back()[0], radius * nrm.back()[1], radius * nrm.back()[2]});
  }
}

Expr splineField(const std::shared_ptr<const VolumeSpline>& s) {
  return fieldCall(s, Expr::x(0), Expr::x(1), Expr::x(2));
}

void expectInterpolates(size_t n, unsigned seed) {
  auto c = randomPoints(n, seed);
  std::vector<double> v;
  for (auto& p : c) v.push_back(smooth(p));
  auto s = VolumeSpline::fit(c, v);
  EXPECT_EQ(s->numDense(), std::min(n, VolumeSpline::kMaxDense));
  double worst = 0.0;
  for (size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(s->value(c[i].data()) - v[i]));
  EXPECT_LE(worst, 1e-9) << n << " centres";
  EXPECT_EQ(worst, s->maxResidual());
  // Through a tape and the batch evaluator, in the same bits.
  TapePtr t = Tape::compile(splineField(s), 3);
  BatchEvaluator<double> be;
  be.reserve(*t);
  const size_t count = std::min<size_t>(n, BatchEvaluator<double>::kBatch);
  for (size_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) be.in(uint32_t(k))[i] = c[i][size_t(k)];
  const double* out = be.eval(*t, count);
  for (size_t i = 0; i < count; ++i) EXPECT_EQ(out[i], s->value(c[i].data())) << i;
}

TEST(VolumeSpline, InterpolatesEveryCentreDense) { expectInterpolates(600, 1); }

TEST(VolumeSpline, InterpolatesEveryCentreTwoLevels) { expectInterpolates(6000, 2); }

TEST(VolumeSpline, ReproducesALinearFunctionExactlyAway) {
  // The polynomial part makes the spline exact on linear data everywhere, not just at centres.
  auto c = randomPoints(300, 3);
  std::vector<double> v;
  for (auto& p : c) v.push_back(1.0 + 2.0 * p[0] - p[1] + 0.5 * p[2]);
  auto s = VolumeSpline::fit(c, v);
  for (const auto& p : randomPoints(50, 4)) EXPECT_NEAR(s->value(p.data()), 1.0 + 2.0 * p[0] - p[1] + 0.5 * p[2], 1e-8);
}

void expectSoundAndDifferentiable(size_t n, unsigned seed) {
  auto c = randomPoints(n, seed);
  std::vector<double> v;
  for (auto& p : c) v.push_back(smooth(p));
  auto s = VolumeSpline::fit(c, v);
  TapePtr t = Tape::compile(splineField(s), 3);
  IntervalEvaluator ie;
  GradientEvaluator ge;
  PointEvaluator pe;
  std::mt19937_64 rng(seed + 100);
  std::uniform_real_distribution<double> u(-1.5, 2.5), w(0.0, 0.3), f(0.0, 1.0);
  for (int b = 0; b < 200; ++b) {
    Interval box[3];
    for (auto& iv : box) {
      const double lo = u(rng);
      iv = Interval(lo, lo + w(rng));
    }
    const Interval r = ie.eval(*t, box);
    for (int k = 0; k < 20; ++k) {
      double x[3];
      for (int a = 0; a < 3; ++a) x[a] = box[a].lo + f(rng) * box[a].width();
      const double val = pe.eval(*t, x);
      ASSERT_TRUE(r.contains(val)) << val << " not in [" << r.lo << ", " << r.hi << "]";
    }
  }
  for (int k = 0; k < 30; ++k) {
    double x[3] = {u(rng), u(rng), u(rng)}, g[3];
    ge.eval(*t, x, g);
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-6;
      double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
      xp[a] += h, xm[a] -= h;
      EXPECT_NEAR(g[a], (s->value(xp) - s->value(xm)) / (2 * h), 1e-5 * std::max(1.0, std::fabs(g[a])));
    }
  }
}

TEST(VolumeSpline, BoundsAreSoundAndGradientIsRightDense) { expectSoundAndDifferentiable(400, 5); }

TEST(VolumeSpline, BoundsAreSoundAndGradientIsRightTwoLevels) { expectSoundAndDifferentiable(4000, 6); }

TEST(VolumeSpline, BoundsShrinkWithTheBox) {
  auto c = randomPoints(500, 7);
  std::vector<double> v;
  for (auto& p : c) v.push_back(smooth(p));
  auto s = VolumeSpline::fit(c, v);
  const double x[3] = {0.3, 0.4, 0.2};
  double prev = INFINITY;
  for (double h : {0.1, 0.01, 0.001}) {
    Interval box[3] = {{x[0] - h, x[0] + h}, {x[1] - h, x[1] + h}, {x[2] - h, x[2] + h}};
    const Interval r = s->bound(box);
    EXPECT_LT(r.width(), prev);
    prev = r.width();
  }
  EXPECT_LT(prev, 0.05);  // the mean-value form: quadratic in the box size
}

TEST(VolumeSpline, RejectsBadData) {
  auto c = randomPoints(20, 8);
  std::vector<double> v(20, 1.0);
  c[7] = c[3];
  try {
    VolumeSpline::fit(c, v);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("centre 4 and centre 8 coincide"), std::string::npos) << e.what();
  }
  std::vector<Point3> flat;
  for (int i = 0; i < 10; ++i) flat.push_back({double(i), double(i * i % 7), 0.0});
  EXPECT_THROW(VolumeSpline::fit(flat, std::vector<double>(10, 0.0)), std::invalid_argument);
  EXPECT_THROW(VolumeSpline::fit(randomPoints(3, 9), {1, 2, 3}), std::invalid_argument);
  EXPECT_THROW(VolumeSpline::fit(randomPoints(5, 9), {1, 2, 3}), std::invalid_argument);
  std::vector<Point3> p(2, {0, 0, 0}), nrm(2, {0, 0, 0});
  std::vector<Point3> cc;
  EXPECT_THROW(offSurfacePoints(p, nrm, 0.1, cc, v), std::invalid_argument);
}

TEST(VolumeSpline, SameDataSameNode) {
  auto c = randomPoints(50, 10);
  std::vector<double> v;
  for (auto& p : c) v.push_back(smooth(p));
  EXPECT_TRUE(splineField(VolumeSpline::fit(c, v)).same(splineField(VolumeSpline::fit(c, v))));
  v[0] += 1.0;
  auto other = VolumeSpline::fit(c, v);
  v[0] -= 1.0;
  EXPECT_FALSE(splineField(VolumeSpline::fit(c, v)).same(splineField(other)));
}

// Pasko-Survey reconstruction: 2,000 points of the sphere of radius 1 with normals, off-surface
// points at +-0.05; the mesh of the spline's zero set at voxel 1/32 lies within half a voxel of
// the sphere.
TEST(VolumeSpline, SphereFrom2000SurfacePointsWithinHalfAVoxel) {
  std::vector<Point3> p, nrm, c;
  std::vector<double> v;
  spherePoints(2000, 1.0, p, nrm);
  offSurfacePoints(p, nrm, 0.05, c, v);
  ASSERT_EQ(c.size(), 6000u);
  auto s = VolumeSpline::fit(c, v);
  EXPECT_LE(s->maxResidual(), 1e-9);
  TapePtr t = Tape::compile(splineField(s), 3);
  const double voxel = 1.0 / 32.0;
  GridSpec g;
  g.origin = {-1.25, -1.25, -1.25};
  g.voxel = voxel;
  g.dims = {81, 81, 81};
  Mesh m = meshGrid(t, g);
  ASSERT_GT(m.triangles.size(), 1000u);
  EXPECT_EQ(mesh_checks::checkEdgePairs(m.triangles, m.positions.size()), "");
  double worst = 0.0;
  for (const auto& q : m.positions) worst = std::max(worst, std::fabs(mesh_checks::norm(q) - 1.0));
  EXPECT_LE(worst, 0.5 * voxel);
  std::printf("sphere from 2000 points: %zu vertices, max |r - 1| = %.5f (voxel %.5f)\n", m.positions.size(), worst,
              voxel);
  // Inside is positive: the centre, and a point well outside is negative.
  const double o[3] = {0, 0, 0}, far[3] = {1.2, 0, 0};
  EXPECT_GT(s->value(o), 0.0);
  EXPECT_LT(s->value(far), 0.0);
}

}  // namespace
}  // namespace frep
