// frOpen and frClose (Roerdink-Minkowski §I, §IV) against closed forms: the closing of a box by
// a ball is the box; its opening is the box with edges and corners rounded by the ball (the
// eroded box plus the ball).
#include <algorithm>
#include <cmath>
#include <random>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const std::string kShapes =
    "blk(x[3], a[1]) { blk = frBlock(x, 2, 1.5, 1); }\n"
    "ball(x[3], a[1]) { ball = frBall(x, 0.3); }\n";
const double kEdge[3] = {2, 1.5, 1}, kR = 0.3;

// Signed distance to the box [0, e]: positive inside.
double boxDistance(const double* p, const double* lo, const double* hi) {
  double out2 = 0, in = 1e300;
  for (int i = 0; i < 3; ++i) {
    const double d = std::max(0.0, std::max(lo[i] - p[i], p[i] - hi[i]));
    out2 += d * d;
    in = std::min(in, std::min(p[i] - lo[i], hi[i] - p[i]));
  }
  return out2 > 0 ? -std::sqrt(out2) : in;
}

std::vector<std::array<double, 3>> randomPoints(int n) {
  std::mt19937 rng(33);
  std::uniform_real_distribution<double> u(-0.5, 2.5);
  std::vector<std::array<double, 3>> p(size_t(n), std::array<double, 3>{});
  for (auto& q : p) q = {u(rng), u(rng) * 0.8, u(rng) * 0.6};
  return p;
}

TEST(FrMorphology, ClosingOfABoxByABallIsTheBox) {
  Model m = compileOk(kShapes + "my_model(x[3], a[1]) { my_model = frClose(x, blk, ball); }");
  EXPECT_FALSE(hasExtremum(m.field));  // both steps take the exact algebra
  const double lo[3] = {0, 0, 0};
  int n = 0;
  for (const auto& p : randomPoints(3000)) {
    const double d = boxDistance(p.data(), lo, kEdge);
    if (std::fabs(d) < 1e-9) continue;
    EXPECT_EQ(evalModel(m, {p[0], p[1], p[2]}) >= 0, d > 0) << p[0] << " " << p[1] << " " << p[2];
    ++n;
  }
  EXPECT_GT(n, 2900);
}

// Opening = {p : dist(p, [r, e - r]) <= r}; its volume (Steiner) is
// a'b'c' + 2r (a'b' + b'c' + c'a') + pi r^2 (a' + b' + c') + 4/3 pi r^3, a' = a - 2r.
TEST(FrMorphology, OpeningOfABoxByABallRoundsItsEdges) {
  Model m = compileOk(kShapes + "my_model(x[3], a[1]) { my_model = frOpen(x, blk, ball); }");
  const double lo[3] = {kR, kR, kR}, hi[3] = {kEdge[0] - kR, kEdge[1] - kR, kEdge[2] - kR};
  const double box[3] = {0, 0, 0};
  int n = 0, rounded = 0;
  for (const auto& p : randomPoints(400)) {
    const double d = kR + boxDistance(p.data(), lo, hi);  // >= 0: in the opening
    if (std::fabs(d) < 1e-3) continue;                    // the search's tolerance, if it searches
    const bool in = evalModel(m, {p[0], p[1], p[2]}) >= 0;
    EXPECT_EQ(in, d > 0) << p[0] << " " << p[1] << " " << p[2];
    rounded += boxDistance(p.data(), box, kEdge) > 0 && d < 0;  // in the box, cut off by the opening
    ++n;
  }
  EXPECT_GT(n, 380);
  EXPECT_GT(rounded, 0);
  // A corner of the box is cut; the point at distance r from the eroded corner along the diagonal
  // is on the opening's boundary.
  const double s = kR - kR / std::sqrt(3.0);
  EXPECT_LT(evalModel(m, {s - 0.01, s - 0.01, s - 0.01}), 0);
  EXPECT_GT(evalModel(m, {s + 0.01, s + 0.01, s + 0.01}), 0);
}

TEST(FrMorphology, Errors) {
  CompileResult r = compile(kShapes + "my_model(x[3], a[1]) { my_model = frOpen(x, blk); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("frOpen takes (x, A, B"), std::string::npos) << allDiagnostics(r);
  r = compile(kShapes + "my_model(x[3], a[1]) { my_model = frClose(x, blk, 2); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("(B) must be the name of an object"), std::string::npos) << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
