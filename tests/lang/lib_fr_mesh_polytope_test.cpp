// A closed mesh (the cube of six flat Bezier patches) ⊕ / ⊖ a convex polytope (hfBlock) through
// the language: frMinkowski, frMinkowskiDiff, frMorphMinkowski and frMinkowskiSum take the exact
// construction of minkowski_algebra/mesh_convex_sum.h (no extremum node, a report line), with
// values against the analytic distance to the resulting box.
#include <algorithm>
#include <cmath>
#include <random>

#include "frep/minkowski_algebra/registry.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const std::string kCube = kBezierCube +
    "blk(x[3], a[1]) { array v[3]; v = [-0.1, -0.2, 0]; blk = hfBlock(x, v, 0.3, 0.2, 0.1); }\n"
    "ball(x[3], a[1]) { ball = frBall(x, 0.15); }\n";

// Signed distance to the box [lo, hi], positive inside.
double boxDistance(const std::array<double, 3>& p, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  double out2 = 0, in = 1e300;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(0.0, std::max(lo[k] - p[k], p[k] - hi[k]));
    out2 += d * d;
    in = std::min(in, std::min(p[k] - lo[k], hi[k] - p[k]));
  }
  return out2 > 0 ? -std::sqrt(out2) : in;
}

std::vector<std::array<double, 3>> randomPoints(int n, double lo, double hi) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<std::array<double, 3>> p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

// Checks signs everywhere and the values where the field is exact (outside, or inside).
void expectBox(const Model& m, const std::array<double, 3>& lo, const std::array<double, 3>& hi, bool exactInside) {
  EXPECT_FALSE(hasExtremum(m.field));
  int exact = 0;
  for (const auto& p : randomPoints(1500, -0.6, 1.8)) {
    const double f = evalModel(m, {p[0], p[1], p[2]}), e = boxDistance(p, lo, hi);
    if (std::fabs(e) < 1e-9) continue;
    ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
    if ((e > 0) == exactInside) {
      EXPECT_NEAR(f, e, 1e-9) << p[0] << " " << p[1] << " " << p[2];
      ++exact;
    } else {
      EXPECT_LE(std::fabs(f), std::fabs(e) + 1e-9);  // the other side: a lower bound of the distance
    }
  }
  EXPECT_GT(exact, 30);
}

TEST(FrMeshPolytope, MeshPlusBlockIsTheGrownBoxExactlyOutside) {
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowski(x, cube, blk); }");
  expectBox(m, {-0.1, -0.2, 0.0}, {1.2, 1.0, 1.1}, false);
  auto lines = minkowski::describeExact(m.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("exact Minkowski sum"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("boundary pieces"), std::string::npos) << lines[0];
  // The block first: the same solid.
  Model b = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowski(x, blk, cube); }");
  expectBox(b, {-0.1, -0.2, 0.0}, {1.2, 1.0, 1.1}, false);
}

TEST(FrMeshPolytope, MeshMinusBlockIsTheShrunkBoxExactlyInside) {
  // {x : x + B ⊆ [0, 1]^3} = [0.1, 0.8] x [0.2, 1.0] x [0, 0.9].
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, cube, blk); }");
  expectBox(m, {0.1, 0.2, 0.0}, {0.8, 1.0, 0.9}, true);
  auto lines = minkowski::describeExact(m.field);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("exact Minkowski difference"), std::string::npos) << lines[0];
}

TEST(FrMeshPolytope, MorphOfMeshAndBlockIsTheInterpolatedBox) {
  // (1 - t) [0, 1]^3 ⊕ t B, t = 0.25: [t lo_B, (1 - t) + t hi_B].
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMorphMinkowski(x, cube, blk, 0.25); }");
  expectBox(m, {-0.025, -0.05, 0.0}, {0.8, 0.75, 0.775}, false);
}

TEST(FrMeshPolytope, ChainWithABallStaysExact) {
  // (cube ⊕ blk) is exact outside, so ⊕ ball takes the offset path: distance to the box minus r.
  Model m = compileOk(kCube + "my_model(x[3], a[1]) { my_model = frMinkowskiSum(x, cube, blk, ball); }");
  EXPECT_FALSE(hasExtremum(m.field));
  for (const auto& p : randomPoints(800, -0.8, 2.0)) {
    const double e = boxDistance(p, {-0.1, -0.2, 0.0}, {1.2, 1.0, 1.1});
    if (e < 0) EXPECT_NEAR(evalModel(m, {p[0], p[1], p[2]}), e + 0.15, 1e-9);
  }
}

}  // namespace
}  // namespace frep::lang::testing
