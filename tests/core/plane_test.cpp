// Plane lattices by quadtree interval subdivision (frep/sampling/plane.h): every pixel's value is
// the full tape's, bit for bit, whatever the pruning, image size, axes or thread count; sign-only
// images skip decided tiles but never get a sign wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "core/random_csg.h"
#include "frep/evaluators/eval.h"
#include "frep/sampling/plane.h"

using namespace frep;
using frep::testing::randomCsg;
using frep::testing::ringOfSpheres;

namespace {

// The reference: the point evaluator at every pixel, coordinates computed as the lattice says.
std::vector<double> everyPixel(const TapePtr& tape, const PlaneLattice& l) {
  PointEvaluator pe;
  std::vector<double> out(size_t(l.width) * size_t(l.height));
  std::vector<double> x(std::max<uint32_t>(tape->numVars(), 3), 0.0);
  for (int r = 0; r < l.height; ++r)
    for (int c = 0; c < l.width; ++c) {
      for (size_t i = 0; i < x.size(); ++i)
        x[i] = int(i) == l.normal ? l.at : (i >= 3 && i - 3 < l.fixed.size() ? l.fixed[i - 3] : 0.0);
      x[l.u] = l.origin[0] + double(c) * l.step;
      x[l.v] = l.origin[1] + double(l.height - 1 - r) * l.step;
      out[size_t(r) * size_t(l.width) + size_t(c)] = pe.eval(*tape, x.data());
    }
  return out;
}

size_t bitDifferences(const std::vector<double>& a, const std::vector<double>& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(double)) != 0;
  return n;
}

PlaneLattice lattice(int w, int h, uint32_t u = 0, uint32_t v = 1, int normal = 2, double at = 0.1) {
  PlaneLattice l;
  l.u = u, l.v = v, l.normal = normal, l.at = at;
  l.origin[0] = -2.0, l.origin[1] = -1.9;
  l.step = 3.9 / double(std::max(w, h) - 1);
  l.width = w, l.height = h;
  return l;
}

}  // namespace

TEST(Plane, RandomCsgMatchesEveryPixelBitForBit) {
  std::mt19937_64 rng(7);
  for (int m = 0; m < 12; ++m) {
    TapePtr tape = Tape::compile(randomCsg(rng, 7), 3);
    const uint32_t axes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    const auto& ax = axes[m % 3];
    const int normal = 3 - int(ax[0]) - int(ax[1]);
    PlaneLattice l = lattice(97 + 13 * m, 131 - 5 * m, ax[0], ax[1], normal, -0.3 + 0.05 * m);
    PlaneStats st;
    std::vector<double> got = evaluatePlane(tape, l, {}, &st);
    EXPECT_EQ(bitDifferences(got, everyPixel(tape, l)), 0u) << "model " << m;
    EXPECT_EQ(st.pointEvals, uint64_t(l.width) * uint64_t(l.height));
  }
}

TEST(Plane, PruningShortensTheTapeNearTheSurface) {
  TapePtr tape = Tape::compile(ringOfSpheres(64), 3);
  PlaneLattice l = lattice(512, 512);
  PlaneStats st;
  std::vector<double> got = evaluatePlane(tape, l, {}, &st);
  EXPECT_EQ(bitDifferences(got, everyPixel(tape, l)), 0u);
  const double avg = double(st.tapeInstrs) / double(st.tapeBatches);
  EXPECT_LT(avg, 0.3 * double(tape->size())) << "average pruned tape " << avg << " of " << tape->size();
}

TEST(Plane, ThreadCountDoesNotChangeABit) {
  std::mt19937_64 rng(11);
  TapePtr tape = Tape::compile(randomCsg(rng, 8), 3);
  PlaneLattice l = lattice(300, 211);
  PlaneOptions one, two, any;
  one.threads = 1, two.threads = 2, any.threads = 0;
  std::vector<double> a = evaluatePlane(tape, l, one), b = evaluatePlane(tape, l, two), c = evaluatePlane(tape, l, any);
  EXPECT_EQ(bitDifferences(a, b), 0u);
  EXPECT_EQ(bitDifferences(a, c), 0u);
}

TEST(Plane, SignOnlySkipsDecidedTilesAndKeepsEverySign) {
  TapePtr tape = Tape::compile(ringOfSpheres(16), 3);
  PlaneLattice l = lattice(400, 400);
  PlaneOptions o;
  o.signOnly = true;
  PlaneStats st;
  std::vector<double> mask = evaluatePlane(tape, l, o, &st);
  std::vector<double> ref = everyPixel(tape, l);
  size_t wrong = 0, skipped = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (std::isinf(mask[i])) ++skipped;
    else EXPECT_EQ(std::memcmp(&mask[i], &ref[i], sizeof(double)), 0);
    wrong += (mask[i] >= 0) != (ref[i] >= 0);
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(skipped + st.pointEvals, ref.size());
  EXPECT_GT(skipped, ref.size() / 2) << "most of the image is far from the ring";
}

TEST(Plane, HigherDimensionalModelUsesTheFixedCoordinates) {
  // A 4D ball whose 3D section at x[3] = w has radius sqrt(1 - w^2).
  Expr r2 = square(Expr::x(0)) + square(Expr::x(1)) + square(Expr::x(2)) + square(Expr::x(3));
  TapePtr tape = Tape::compile(1.0 - r2, 4);
  PlaneLattice l = lattice(64, 64);
  l.fixed = {0.6};
  std::vector<double> got = evaluatePlane(tape, l);
  EXPECT_EQ(bitDifferences(got, everyPixel(tape, l)), 0u);
  EXPECT_NEAR(got[size_t(32) * 64 + 32] , 1.0 - 0.36 - 0.01, 0.01);
}

TEST(Plane, RejectsBadLattices) {
  TapePtr tape = Tape::compile(ringOfSpheres(4), 3);
  PlaneLattice l = lattice(8, 8);
  l.width = 0;
  EXPECT_THROW(evaluatePlane(tape, l), std::invalid_argument);
  l = lattice(8, 8);
  l.step = 0;
  EXPECT_THROW(evaluatePlane(tape, l), std::invalid_argument);
  l = lattice(8, 8);
  l.v = l.u;
  EXPECT_THROW(evaluatePlane(tape, l), std::invalid_argument);
}
