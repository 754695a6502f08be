// Sign images in float with the certified double fallback (PlaneOptions::floatSigns): every
// pixel's sign class is the double path's, on closed-form models and on models built so that
// pixels lie exactly on the surface or closer to it than float can tell; and the error bound of
// frep/evaluators/float_error.h holds at random points against the two batch evaluators.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/random_csg.h"
#include "frep/evaluators/eval.h"
#include "frep/evaluators/float_error.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/plane.h"

using namespace frep;
using frep::testing::randomCsg;
using frep::testing::ringOfSpheres;

namespace {

// Random CSG in the ops the float bound covers: spheres (squares, or sqrt distances) and boxes
// (abs, max, a product), under union max, intersection min and difference min(a, -b).
Expr coveredCsg(std::mt19937_64& rng, int depth) {
  std::uniform_real_distribution<double> u(-1.5, 1.5), r(0.1, 0.8);
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  if (depth == 0) {
    const double cx = u(rng), cy = u(rng), cz = 0.3 * u(rng), rad = r(rng);
    switch (rng() % 3) {
      case 0:
        return rad * rad - square(x - cx) - square(y - cy) - square(z - cz);
      case 1:
        return rad - sqrt(square(x - cx) + square(y - cy) + square(z - cz));
      default:
        return -max(abs(x - cx) - rad, abs((y - cy) * 1.3) - 0.5 * rad);
    }
  }
  Expr a = coveredCsg(rng, depth - 1), b = coveredCsg(rng, depth - 1);
  switch (rng() % 3) {
    case 0:
      return max(a, b);
    case 1:
      return min(a, b);
    default:
      return min(a, -b);
  }
}

int signClass(double f) { return std::isnan(f) ? 2 : f >= 0 ? 1 : 0; }

PlaneLattice lattice(int side, double origin, double step) {
  PlaneLattice l;
  l.normal = 2, l.at = 0.0;
  l.origin[0] = l.origin[1] = origin;
  l.step = step;
  l.width = l.height = side;
  return l;
}

// Sign classes of the float path against the double sign-only path and the double values.
PlaneStats expectSameSigns(const TapePtr& tape, const PlaneLattice& l, int threads = 1) {
  PlaneOptions values, dbl, flt;
  values.threads = dbl.threads = flt.threads = threads;
  dbl.signOnly = flt.signOnly = true;
  flt.floatSigns = true;
  PlaneStats st;
  const std::vector<double> ref = evaluatePlane(tape, l, values);
  const std::vector<double> d = evaluatePlane(tape, l, dbl);
  const std::vector<double> f = evaluatePlane(tape, l, flt, &st);
  size_t wrong = 0;
  for (size_t i = 0; i < ref.size(); ++i)
    wrong += signClass(ref[i]) != signClass(f[i]) || signClass(d[i]) != signClass(f[i]);
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(st.floatPixels + st.doublePixels + st.decidedPixels, ref.size());
  return st;
}

}  // namespace

TEST(PlaneFloat, RingOfSpheresAndRandomCsgHaveTheDoubleSigns) {
  TapePtr ring = Tape::compile(ringOfSpheres(9), 3);
  ASSERT_TRUE(FloatErrorBound::supports(*ring));
  const PlaneStats st = expectSameSigns(ring, lattice(300, -2.0, 4.0 / 299), 2);
  EXPECT_GT(st.floatPixels, 0u);
  std::mt19937_64 rng(11);
  uint64_t certified = 0;  // random intersections are often empty: counted over all models
  for (int m = 0; m < 10; ++m) {
    TapePtr covered = Tape::compile(coveredCsg(rng, 4), 3);
    ASSERT_TRUE(FloatErrorBound::supports(*covered));
    certified += expectSameSigns(covered, lattice(157, -1.7, 3.4 / 156)).floatPixels;
    // with selects (not covered): the double path throughout
    TapePtr other = Tape::compile(randomCsg(rng, 6), 3);
    if (!FloatErrorBound::supports(*other))
      EXPECT_EQ(expectSameSigns(other, lattice(157, -1.7, 3.4 / 156)).floatPixels, 0u);
  }
  EXPECT_GT(certified, 10000u);
}

// x^2 + y^2 - 1/4 on a dyadic lattice: pixels (0, +-1/2), (+-1/2, 0) are exactly on the circle
// (f = 0 in both precisions), and the diagonal half-plane x - y is 0 on a whole pixel diagonal.
TEST(PlaneFloat, PixelsExactlyOnTheSurfaceFallBackToDouble) {
  Expr x = Expr::x(0), y = Expr::x(1);
  for (const Expr& e : {square(x) + square(y) - 0.25, x - y, min(x - y, 0.25 - square(x) - square(y))}) {
    TapePtr tape = Tape::compile(e, 3);
    const PlaneStats st = expectSameSigns(tape, lattice(129, -1.0, 1.0 / 64));
    EXPECT_GT(st.doublePixels, 0u);
    EXPECT_GT(st.floatPixels, 0u);
  }
}

// x^2 - 0.01 at pixels within 4e-9 of x = 0.1: there float's value has the wrong sign at some
// (e.g. x = 0.099999997765: f_double = -4.5e-10, f_float = +9.3e-10), so only the fallback gets
// them right.
TEST(PlaneFloat, PixelsWhereFloatGetsTheSignWrongFallBack) {
  TapePtr tape = Tape::compile(square(Expr::x(0)) - 0.01, 3);
  PlaneLattice l = lattice(64, 0.1 - 4e-9, 1e-10);
  l.origin[1] = -1.0;
  PlaneOptions flt;
  flt.signOnly = flt.floatSigns = true;
  PlaneStats st;
  const std::vector<double> f = evaluatePlane(tape, l, flt, &st);
  BatchEvaluator<float> bf;
  BatchEvaluator<double> bd;
  bf.reserve(*tape), bd.reserve(*tape);
  for (int c = 0; c < l.width; ++c) {
    bd.in(0)[c] = l.origin[0] + double(c) * l.step, bd.in(1)[c] = bd.in(2)[c] = 0.0;
    bf.in(0)[c] = float(bd.in(0)[c]), bf.in(1)[c] = bf.in(2)[c] = 0.0f;
  }
  const float* ff = bf.eval(*tape, size_t(l.width));
  const double* fd = bd.eval(*tape, size_t(l.width));
  int floatWrong = 0;
  for (int c = 0; c < l.width; ++c) {
    floatWrong += signClass(double(ff[c])) != signClass(fd[c]);
    EXPECT_EQ(signClass(f[size_t(c)]), signClass(fd[c])) << "column " << c;  // row 0
  }
  EXPECT_GT(floatWrong, 0);  // the model does what it is for
  EXPECT_GT(st.doublePixels, 0u);
  expectSameSigns(tape, l);
}

// |f_float - f_double| <= bound at random points of random boxes, on models whose values cancel.
TEST(PlaneFloat, ErrorBoundHoldsAtRandomPoints) {
  std::mt19937_64 rng(5);
  std::vector<TapePtr> tapes = {Tape::compile(ringOfSpheres(7), 3)};
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  tapes.push_back(Tape::compile(sqrt(square(x - 0.3) + square(y + 0.7)) - 0.5, 3));
  tapes.push_back(Tape::compile(max(abs(x) - 0.5, abs(y * 3.1) - 0.2) * (x + 1e3) - (z - 1e-3), 3));
  for (int m = 0; m < 6; ++m) tapes.push_back(Tape::compile(coveredCsg(rng, 5), 3));
  std::uniform_real_distribution<double> centre(-2.0, 2.0), half(1e-6, 0.5), unit(0.0, 1.0);
  FloatErrorBound fe;
  BatchEvaluator<float> bf;
  BatchEvaluator<double> bd;
  for (const TapePtr& tape : tapes) {
    ASSERT_TRUE(FloatErrorBound::supports(*tape));
    for (int trial = 0; trial < 40; ++trial) {
      Interval box[3];
      for (auto& b : box) {
        const double c = centre(rng), h = half(rng);
        b = Interval(c - h, c + h);
      }
      const double bound = fe.bound(*tape, box);
      ASSERT_TRUE(std::isfinite(bound));
      bf.reserve(*tape), bd.reserve(*tape);
      const size_t n = BatchEvaluator<float>::kBatch;
      for (size_t k = 0; k < n; ++k)
        for (uint32_t v = 0; v < 3; ++v) {
          const double p = box[v].lo + unit(rng) * (box[v].hi - box[v].lo);
          bd.in(v)[k] = std::min(std::max(p, box[v].lo), box[v].hi);
          bf.in(v)[k] = float(bd.in(v)[k]);
        }
      const float* f = bf.eval(*tape, n);
      const double* d = bd.eval(*tape, n);
      for (size_t k = 0; k < n; ++k) ASSERT_LE(std::fabs(double(f[k]) - d[k]), bound) << "lane " << k;
    }
  }
}

TEST(PlaneFloat, UnsupportedOpsStayInDouble) {
  TapePtr tape = Tape::compile(sin(Expr::x(0) * 3.0) - Expr::x(1), 3);
  EXPECT_FALSE(FloatErrorBound::supports(*tape));
  const PlaneStats st = expectSameSigns(tape, lattice(64, -1.0, 2.0 / 63));
  EXPECT_EQ(st.floatPixels, 0u);
}

// R-functions (any parameter in (-1, 1)) and divisions by values away from 0: the bound covers
// the float and double batch values at random points of random boxes (the blended unions and
// blocks of examples/chair.hf are built of these), and stays useful (far below the values).
TEST(PlaneFloat, BoundCoversRFunctionsAndDivisions) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  auto block = [&](double cx, double cy, double cz, double h, double al) {
    return rIntersection(rIntersection(h - square(x - cx), h - square(y - cy), al), h - square(z - cz), al);
  };
  const Expr b1 = block(0.1, -0.2, 0.3, 0.3, 0.0), b2 = block(-0.4, 0.2, 0.1, 0.2, 0.0);
  const Expr u = rUnion(b1, b2, 0.0);
  // hfBlendUni's displacement a0 / (1 + (f1/a1)^2 + (f2/a2)^2) on a union
  const Expr blend = u + 0.02 / (1.0 + square(b1 / 0.1) + square(b2 / 0.1));
  const std::vector<Expr> models{u, blend, rUnion(block(0.0, 0.0, 0.0, 0.25, 0.3), b2, -0.5),
                                 rIntersection(b1, -b2, 0.7), x / (2.0 + y * y) - z / (z * z + 0.5)};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> c(-1.2, 1.2), w(0.0, 1.0), t(0.0, 1.0);
  BatchEvaluator<float> bf;
  BatchEvaluator<double> bd;
  FloatErrorBound fb;
  for (const Expr& e : models) {
    TapePtr tape = Tape::compile(e, 3);
    ASSERT_TRUE(FloatErrorBound::supports(*tape)) << toString(e);
    bf.reserve(*tape), bd.reserve(*tape);
    int finite = 0, useful = 0;
    for (int box = 0; box < 200; ++box) {
      Interval iv[3];
      const double side = std::pow(10.0, -4 * w(rng));  // 1e-4 to 1
      for (int k = 0; k < 3; ++k) iv[k] = {c(rng), 0.0}, iv[k].hi = iv[k].lo + side;
      const double B = fb.bound(*tape, iv);
      const size_t n = BatchEvaluator<double>::kBatch;
      for (int k = 0; k < 3; ++k)
        for (size_t i = 0; i < n; ++i) {
          bd.in(uint32_t(k))[i] = iv[k].lo + (iv[k].hi - iv[k].lo) * t(rng);
          bf.in(uint32_t(k))[i] = float(bd.in(uint32_t(k))[i]);
        }
      const float* ff = bf.eval(*tape, n);
      const double* fd = bd.eval(*tape, n);
      if (!std::isfinite(B)) continue;
      ++finite;
      size_t below = 0;
      for (size_t i = 0; i < n; ++i) {
        ASSERT_LE(std::fabs(double(ff[i]) - fd[i]), B) << toString(e) << " at " << bd.in(0)[i] << ", " << bd.in(1)[i];
        below += std::fabs(fd[i]) > 100 * B;
      }
      useful += below > n / 2;
    }
    EXPECT_GT(finite, 150) << toString(e);
    EXPECT_GT(useful, 100) << toString(e);
  }
}
