// frHull against closed forms: the hull of two balls is a capsule, the hull of a box is the box,
// both within the bound the function states (lang/src/library/fr_hull.cpp, docs/language.md).
#include <algorithm>
#include <cmath>
#include <random>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

// The model's field as one tape, evaluated at many points (evalModel compiles per point).
struct Field {
  explicit Field(const Model& m) : tape(Tape::compile(m.field, 3)) {}
  double operator()(double x, double y, double z) {
    const double p[3] = {x, y, z};
    return ev.eval(*tape, p);
  }
  TapePtr tape;
  PointEvaluator ev;
};

std::vector<std::array<double, 3>> randomPoints(int n, double lo, double hi) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<std::array<double, 3>> p(size_t(n), std::array<double, 3>{});
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

// The support's overestimate: one leaf box's diagonal (boxes of [-1000, 1000]^3 halved 17
// times for these sizes).
const double kLeaf = std::sqrt(3.0) * 2000.0 / (1 << 17);

// Distance from the capsule of radius 1 around the segment (-1, 0, 0)-(1, 0, 0); < 0 inside.
double capsule(const std::array<double, 3>& p) {
  const double x = std::clamp(p[0], -1.0, 1.0);
  return std::sqrt((p[0] - x) * (p[0] - x) + p[1] * p[1] + p[2] * p[2]) - 1.0;
}

TEST(FrHull, TwoBallsMakeACapsule) {
  for (int n : {9, 25}) {
    Model m = compileOk(
        "two(x[3], a[1]) { two = max(1 - (x[1] + 1)^2 - x[2]^2 - x[3]^2, 1 - (x[1] - 1)^2 - x[2]^2 - x[3]^2); }\n"
        "my_model(x[3], a[1]) { my_model = frHull(x, two, " +
        std::to_string(n) + "); }");
    Field f(m);
    // d <= (e + 4 R sin(θ/2)) / cos θ, R = 2 (the ball around the capsule at the origin).
    const double theta = std::atan(std::sqrt(2.0) / n);
    const double bound = (kLeaf + 8 * std::sin(theta / 2)) / std::cos(theta);
    int in = 0, out = 0;
    double reach = 0;  // farthest point of the polytope seen outside the capsule
    for (const auto& p : randomPoints(4000, -3, 3)) {
      const double d = capsule(p);
      const bool inside = f(p[0], p[1], p[2]) >= 0;
      if (d <= 0) EXPECT_TRUE(inside) << p[0] << " " << p[1] << " " << p[2];  // contains the hull
      if (d > bound) EXPECT_FALSE(inside) << p[0] << " " << p[1] << " " << p[2] << " n " << n;
      if (inside && d > 0) reach = std::max(reach, d);
      in += d <= 0;
      out += d > bound;
    }
    EXPECT_GT(in, 100);
    EXPECT_GT(out, 1000);
    EXPECT_LE(reach, bound);
    // The capsule's waist (0, 1, 0) is on the hull (not in either ball's interior, yet in the
    // hull): the polytope holds it.
    EXPECT_GE(f(0, 0.999, 0), 0);
    EXPECT_LT(f(0, 1 + bound + 1e-9, 0), 0);
  }
}

// Odd n includes the axis directions: the hull of a box is the box, to one leaf box.
TEST(FrHull, BoxIsItsOwnHull) {
  Model m = compileOk(
      "blk(x[3], a[1]) { blk = min(min(min(x[1], 2 - x[1]), min(x[2], 1 - x[2])), min(x[3], 1 - x[3])); }\n"
      "my_model(x[3], a[1]) { my_model = frHull(x, blk); }");
  Field f(m);
  for (const auto& p : randomPoints(3000, -0.5, 2.5)) {
    double out2 = 0;
    const double hi[3] = {2, 1, 1};
    bool inBox = true;
    for (int i = 0; i < 3; ++i) {
      const double e = std::max(0.0, std::max(-p[size_t(i)], p[size_t(i)] - hi[i]));
      out2 += e * e;
      inBox = inBox && p[size_t(i)] >= 0 && p[size_t(i)] <= hi[i];
    }
    const bool inside = f(p[0], p[1], p[2]) >= 0;
    if (inBox) EXPECT_TRUE(inside);
    if (std::sqrt(out2) > kLeaf) EXPECT_FALSE(inside) << p[0] << " " << p[1] << " " << p[2];
  }
}

TEST(FrHull, Errors) {
  CompileResult r = compile("my_model(x[3], a[1]) { my_model = frHull(x, 1); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("frHull: argument 2 (A) must be the name of a 3D object"), std::string::npos)
      << allDiagnostics(r);
  r = compile("h(x[3], a[1]) { h = x[1]; }\nmy_model(x[3], a[1]) { my_model = frHull(x, h); }", "t.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("is not bounded"), std::string::npos) << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
