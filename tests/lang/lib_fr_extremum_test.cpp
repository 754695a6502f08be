// The fr* extremum extensions (lang/src/library/fr_extremum.cpp): object operands, automatic
// bounding boxes, and the exact answers of issue 6 at a few points each (coarse tolerances).
#include <algorithm>
#include <array>
#include <cmath>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const std::string kBall3 = "ball(x[3], a[1]) { ball = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n";
// Box [-1,1] x [-0.5,0.5] x [-0.25,0.25] as an exact-min intersection (1-Lipschitz).
const std::string kBox3 =
    "box(x[3], a[1]) { box = min(min(1 - abs(x[1]), 0.5 - abs(x[2])), 0.25 - abs(x[3])); }\n";

double at(const Model& m, std::vector<double> x) { return evalModel(m, std::move(x)); }

TEST(FrExtremum, BallPlusBallHasRadiusTwo) {
  Model m = compileOk(kBall3 + "my_model(x[3], a[1]) { my_model = frMinkowski(x, ball, ball); }");
  EXPECT_GT(at(m, {1.99, 0, 0}), 0);
  EXPECT_LT(at(m, {2.01, 0, 0}), 0);
  EXPECT_GT(at(m, {0, 1.2, 1.6 * 0.99}), 0);  // |X| = 1.99..
  EXPECT_LT(at(m, {0, 1.21, 1.61}), 0);
  EXPECT_GT(at(m, {0, 0, 0}), 0);
}

TEST(FrExtremum, BoxPlusBallIsTheRoundedBox) {
  Model m = compileOk(kBox3 +
                      "disc(x[3], a[1]) { disc = 0.25 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
                      "my_model(x[3], a[1]) { array o[2]; o = [0, 0.002]; "
                      "my_model = frMinkowski(x, box, disc, o); }");
  const double r = 0.5;
  // Faces.
  EXPECT_GT(at(m, {1 + r - 0.02, 0, 0}), 0);
  EXPECT_LT(at(m, {1 + r + 0.02, 0, 0}), 0);
  EXPECT_GT(at(m, {0, 0.25 + r - 0.02 + 0.25, 0}), 0);
  EXPECT_LT(at(m, {0, 0.5 + r + 0.02, 0}), 0);
  // Edge (x, y): a quarter cylinder around (1, 0.5).
  const double e = r / std::sqrt(2.0);
  EXPECT_GT(at(m, {1 + e - 0.02, 0.5 + e - 0.02, 0}), 0);
  EXPECT_LT(at(m, {1 + e + 0.02, 0.5 + e + 0.02, 0}), 0);
  // Corner: a ball octant around (1, 0.5, 0.25).
  const double c = r / std::sqrt(3.0);
  EXPECT_GT(at(m, {1 + c - 0.02, 0.5 + c - 0.02, 0.25 + c - 0.02}), 0);
  EXPECT_LT(at(m, {1 + c + 0.02, 0.5 + c + 0.02, 0.25 + c + 0.02}), 0);
  // The sharp box corner would be inside; the rounded one is not.
  EXPECT_LT(at(m, {1 + 0.45, 0.5 + 0.45, 0}), 0);
}

TEST(FrExtremum, BoxMinusBallIsTheShrunkBox) {
  Model m = compileOk(kBox3 +
                      "b(x[3], a[1]) { b = 0.01 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
                      "my_model(x[3], a[1]) { my_model = frMinkowskiDiff(x, box, b); }");
  EXPECT_GT(at(m, {0.88, 0, 0}), 0);
  EXPECT_LT(at(m, {0.92, 0, 0}), 0);
  EXPECT_GT(at(m, {0, 0.38, 0}), 0);
  EXPECT_LT(at(m, {0, 0.42, 0}), 0);
  EXPECT_GT(at(m, {0.85, 0.35, 0.1}), 0);
  EXPECT_LT(at(m, {0, 0, 0.17}), 0);
}

TEST(FrExtremum, OffsetOfABox) {
  Model grow = compileOk(kBox3 + "my_model(x[3], a[1]) { my_model = frOffsetR(x, box, 0.2); }");
  EXPECT_GT(at(grow, {1.18, 0, 0}), 0);
  EXPECT_LT(at(grow, {1.22, 0, 0}), 0);
  EXPECT_GT(at(grow, {1.1, 0.6, 0.3}), 0);   // corner region: |(0.1,0.1,0.05)| < 0.2
  EXPECT_LT(at(grow, {1.15, 0.65, 0.4}), 0);  // |(0.15,0.15,0.15)| > 0.2
  Model shrink = compileOk(kBox3 + "my_model(x[3], a[1]) { my_model = frOffsetR(x, box, -0.1); }");
  EXPECT_GT(at(shrink, {0.88, 0, 0}), 0);
  EXPECT_LT(at(shrink, {0.92, 0, 0}), 0);
  EXPECT_LT(at(shrink, {0, 0, 0.17}), 0);
}

TEST(FrExtremum, ProjectionOfA4DBallIsA3DBall) {
  Model m = compileOk(
      "b4(x[4], a[1]) { b4 = 1 - x[1]^2 - x[2]^2 - x[3]^2 - (x[4] - 0.5)^2; }\n"
      "my_model(x[3], a[1]) { my_model = frProject(x, b4, 4); }");
  EXPECT_GT(at(m, {0.98, 0, 0}), 0);
  EXPECT_LT(at(m, {1.02, 0, 0}), 0);
  EXPECT_GT(at(m, {0, 0.5, 0.84}), 0);
  EXPECT_LT(at(m, {0, 0.5, 0.9}), 0);
  // Projecting the 2nd coordinate of a 3D ellipsoid gives a 2D ellipse over (x1, x3).
  Model e = compileOk(
      "el(x[3], a[1]) { el = 1 - x[1]^2 - (x[2]/3)^2 - (x[3]/2)^2; }\n"
      "my_model(x[2], a[1]) { my_model = frProject(x, el, 2); }");
  EXPECT_GT(at(e, {0, 1.95}), 0);
  EXPECT_LT(at(e, {0, 2.05}), 0);
}

TEST(FrExtremum, SweepOfABallAlongASegmentIsACapsule) {
  Model m = compileOk(
      "b(x[3], a[1]) { b = 0.09 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
      "tx(x[1], a[1]) { tx = 2 * x[1]; }\n"
      "zero(x[1], a[1]) { zero = 0; }\n"
      "my_model(x[3], a[1]) { my_model = frSweep(x, b, tx, zero, zero, 0, 1); }");
  EXPECT_GT(at(m, {1, 0.28, 0}), 0);
  EXPECT_LT(at(m, {1, 0.32, 0}), 0);
  EXPECT_GT(at(m, {2.28, 0, 0}), 0);
  EXPECT_LT(at(m, {2.32, 0, 0}), 0);
  EXPECT_GT(at(m, {-0.28, 0, 0}), 0);
  EXPECT_LT(at(m, {-0.32, 0, 0}), 0);
  EXPECT_LT(at(m, {-0.22, 0.22, 0}), 0);  // rounded end, not a cylinder
}

TEST(FrExtremum, TimeVaryingSweepWithRotation) {
  // A 2D bar of half-length 1 turning a quarter turn about the origin sweeps a quarter disc
  // (plus the bar's width); its time coordinate x[3] grows the bar's length with t.
  Model m = compileOk(
      "bar(x[3], a[1]) { bar = min(1 + x[3] - abs(x[1]), 0.05 - abs(x[2])); }\n"
      "zero(x[1], a[1]) { zero = 0; }\n"
      "turn(x[1], a[1]) { turn = 1.5707963 * x[1]; }\n"
      "my_model(x[2], a[1]) { array o[2]; o = [0, 0.001]; "
      "my_model = frSweep(x, bar, zero, zero, turn, 0, 1, o); }");
  EXPECT_GT(at(m, {0, 1.9}), 0);   // at t = 1 the bar is vertical with half-length 2
  EXPECT_LT(at(m, {0, 2.1}), 0);
  EXPECT_GT(at(m, {0.95, 0.0}), 0);
  EXPECT_LT(at(m, {1.1, 0.0}), 0);  // at t = 0 the bar has half-length 1
  EXPECT_LT(at(m, {1.0, -1.0}), 0);
}

TEST(FrExtremum, MorphAtTheEndsIsTheOperands) {
  const std::string ops = kBall3 + kBox3;
  for (double t : {0.0, 1.0}) {
    Model m = compileOk(ops + "my_model(x[3], a[1]) { my_model = frMorphMinkowski(x, ball, box, " +
                        std::to_string(t) + "); }");
    for (auto p : std::vector<std::vector<double>>{{0.95, 0, 0}, {0.5, 0.6, 0}, {0, 0, 0.3}}) {
      double expect = t == 0 ? 1 - p[0] * p[0] - p[1] * p[1] - p[2] * p[2]
                             : std::min(std::min(1 - std::fabs(p[0]), 0.5 - std::fabs(p[1])),
                                        0.25 - std::fabs(p[2]));
      EXPECT_CLOSE(at(m, p), expect);
    }
  }
  // Halfway: (ball / 2) + (box / 2) reaches 0.5 + 0.5 = 1 along x1 and 0.5 + 0.125 along x3.
  Model h = compileOk(ops + "my_model(x[3], a[1]) { array o[2]; o = [0, 0.002]; "
                            "my_model = frMorphMinkowski(x, ball, box, 0.5, o); }");
  EXPECT_GT(at(h, {0.97, 0, 0}), 0);
  EXPECT_LT(at(h, {1.03, 0, 0}), 0);
  EXPECT_GT(at(h, {0, 0, 0.6}), 0);
  EXPECT_LT(at(h, {0, 0, 0.65}), 0);
}

TEST(FrExtremum, GridMethodAndExplicitBox) {
  Model m = compileOk(
      "d(x[2], a[1]) { d = 1 - x[1]^2 - x[2]^2; }\n"
      "my_model(x[2], a[1]) { array o[6]; o = [1, 0.02, -1, 1, -1, 1]; "
      "my_model = frMinkowski(x, d, d, o); }");
  EXPECT_GT(at(m, {1.95, 0}), 0);
  EXPECT_LT(at(m, {2.05, 0}), 0);
}

TEST(FrExtremum, OperandParametersAndClosure) {
  // The operand reads a[1] (its radius): a constant a[1] in the caller binds it...
  const std::string src =
      "b(x[3], a[1]) { b = a[1]^2 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
      "my_model(x[3], a[1]) { my_model = frOffsetR(x, b, 0.5); }\n";
  CompileOptions fixed;
  fixed.params = {1.0};
  Model m = compileOk(src, fixed);
  EXPECT_GT(at(m, {1.45, 0, 0}), 0);
  EXPECT_LT(at(m, {1.55, 0, 0}), 0);
  // ... a free parameter cannot enter the search body.
  CompileResult r = compile(src, "test.hf");
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.diagnostics.front().message.find("reads a[] values that are not known"),
            std::string::npos) << allDiagnostics(r);
  // Closure: the offset of a Minkowski sum, and a 2D result in a 3D object (a prism).
  Model c = compileOk(
      "d(x[2], a[1]) { d = 0.25 - x[1]^2 - x[2]^2; }\n"
      "sum2(x[2], a[1]) { sum2 = frMinkowski(x, d, d); }\n"
      "my_model(x[3], a[1]) { my_model = min(frOffsetR(x, sum2, 0.2), 1 - abs(x[3])); }");
  EXPECT_GT(at(c, {1.15, 0, 0.5}), 0);
  EXPECT_LT(at(c, {1.25, 0, 0.5}), 0);
  EXPECT_LT(at(c, {0, 0, 1.1}), 0);
}

// Keyframe motions: frKeyframe interpolates piecewise linearly and holds the end values.
TEST(FrExtremum, KeyframeInterpolatesPiecewiseLinearly) {
  Model m = compileOk(
      "my_model(x[3], a[1]) { array ts[4], vs[4]; ts = [0, 0.5, 1.5, 2]; vs = [1, 3, -1, -1]; "
      "my_model = frKeyframe(x[1], ts, vs); }");
  const std::vector<std::pair<double, double>> expect = {
      {-1, 1}, {0, 1}, {0.25, 2}, {0.5, 3}, {1.0, 1}, {1.5, -1}, {1.75, -1}, {2, -1}, {3, -1}};
  for (auto [t, v] : expect) {
    SCOPED_TRACE(t);
    EXPECT_CLOSE(at(m, {t, 0, 0}), v);
  }
  // One keyframe: a constant.
  Model c = compileOk(
      "my_model(x[3], a[1]) { array ts[1], vs[1]; ts = [0.3]; vs = [2.5]; my_model = frKeyframe(x[1], ts, vs); }");
  EXPECT_CLOSE(at(c, {-5, 0, 0}), 2.5);
  EXPECT_CLOSE(at(c, {5, 0, 0}), 2.5);
}

// Distance from p to the polyline through `pts` (3D).
double polylineDistance(const std::vector<std::array<double, 3>>& pts, const std::vector<double>& p) {
  double best = 1e300;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    double d[3], q[3], dd = 0, qd = 0;
    for (int k = 0; k < 3; ++k) {
      d[k] = pts[i + 1][k] - pts[i][k];
      q[k] = p[k] - pts[i][k];
      dd += d[k] * d[k];
      qd += q[k] * d[k];
    }
    const double s = std::clamp(qd / dd, 0.0, 1.0);
    double e = 0;
    for (int k = 0; k < 3; ++k) e += (q[k] - s * d[k]) * (q[k] - s * d[k]);
    best = std::min(best, std::sqrt(e));
  }
  return best;
}

// A ball (exact distance, radius 0.3) swept through keyframes along an L-shaped path is the union
// of two capsules: its value is 0.3 - dist(X, path) (up to the certified gap), inside and out.
TEST(FrExtremum, SweepKeysAlongAnLIsTheUnionOfTwoCapsules) {
  const std::string src =
      "ball(x[3], a[1]) { ball = 0.3 - sqrt(x[1]^2 + x[2]^2 + x[3]^2); }\n"
      "my_model(x[3], a[1]) {\n"
      "  array ts[3], ps[9], o[2];\n"
      "  ts = [0, 1, 3];\n"
      "  ps = [0, 0, 0,  2, 0, 0,  2, 1.5, 0];\n"
      "  o = [0, 0.0005];\n"
      "  my_model = frSweepKeys(x, ball, ts, ps, o);\n"
      "}";
  Model m = compileOk(src);
  const std::vector<std::array<double, 3>> path = {{0, 0, 0}, {2, 0, 0}, {2, 1.5, 0}};
  const std::vector<std::vector<double>> pts = {
      {1, 0.1, 0},    {1, 0.29, 0},  {1, 0.31, 0},   {-0.2, 0.2, 0}, {2.25, -0.2, 0}, {2.1, 0.7, 0.2},
      {1.75, 0.7, 0}, {2.3, 1.6, 0}, {2, 1.82, 0},   {1.5, 1.0, 0},  {2.2, 0.2, 0.1}, {0.5, 0, 0.35},
      {3, 3, 3},      {-1, 0, 0},    {2.21, 0.21, 0}};
  for (const auto& p : pts) EXPECT_NEAR(at(m, p), 0.3 - polylineDistance(path, p), 1e-3) << p[0] << "," << p[1];
  // The same path written with frKeyframe motion objects and frSweep gives the same values.
  const std::string viaSweep =
      "ball(x[3], a[1]) { ball = 0.3 - sqrt(x[1]^2 + x[2]^2 + x[3]^2); }\n"
      "px(x[1], a[1]) { array ts[3], v[3]; ts = [0, 1, 3]; v = [0, 2, 2]; px = frKeyframe(x[1], ts, v); }\n"
      "py(x[1], a[1]) { array ts[3], v[3]; ts = [0, 1, 3]; v = [0, 0, 1.5]; py = frKeyframe(x[1], ts, v); }\n"
      "pz(x[1], a[1]) { pz = 0; }\n"
      "my_model(x[3], a[1]) { array o[2]; o = [0, 0.0005]; my_model = frSweep(x, ball, px, py, pz, 0, 3, o); }";
  Model s = compileOk(viaSweep);
  for (const auto& p : pts) EXPECT_NEAR(at(s, p), at(m, p), 1e-3);
}

// The same path swept by HyperFun's own ball (hfSphere, a recognised ball), translation only:
// a union of capsules, no search (path_sweep.h), the exact values; with angles it searches.
TEST(FrExtremum, SweepKeysOfARecognisedBallIsAUnionOfCapsules) {
  const std::string ball = "ball(x[3], a[1]) { array c[3]; c = [0.1, 0, 0]; ball = hfSphere(x, c, 0.3); }\n";
  Model m = compileOk(ball +
                      "my_model(x[3], a[1]) { array ts[3], ps[9]; ts = [0, 1, 3]; "
                      "ps = [0, 0, 0,  2, 0, 0,  2, 1.5, 0]; my_model = frSweepKeys(x, ball, ts, ps); }");
  EXPECT_FALSE(Tape::compile(m.field, 3)->hasExtrema());
  const std::vector<std::array<double, 3>> path = {{0.1, 0, 0}, {2.1, 0, 0}, {2.1, 1.5, 0}};
  for (const auto& p : std::vector<std::vector<double>>{
           {1, 0.1, 0}, {1, 0.29, 0}, {1, 0.31, 0}, {-0.2, 0.2, 0}, {2.25, -0.2, 0}, {2.1, 0.7, 0.2}, {3, 3, 3}})
    EXPECT_NEAR(at(m, p), 0.3 - polylineDistance(path, p), 1e-12) << p[0] << "," << p[1];
  Model turned = compileOk(ball +
                           "my_model(x[3], a[1]) { array ts[2], ps[6], an[6]; ts = [0, 1]; ps = [0, 0, 0, 1, 0, 0]; "
                           "an = [0, 0, 0, 0, 0, 1]; my_model = frSweepKeys(x, ball, ts, ps, an); }");
  EXPECT_TRUE(Tape::compile(turned.field, 3)->hasExtrema());
}

// Rotation keyframes: a 2D bar turned a quarter turn about the origin through a keyframe at
// half way (0 -> pi/4 -> pi/2) equals the expression form; its translation keyframes move it.
TEST(FrExtremum, SweepKeysWithAngles) {
  const std::string bar = "bar(x[2], a[1]) { bar = min(1 - abs(x[1]), 0.05 - abs(x[2])); }\n";
  Model keys = compileOk(bar +
                         "my_model(x[2], a[1]) { array ts[3], ps[6], an[3], o[2]; ts = [0, 0.5, 1]; "
                         "ps = [0, 0, 0, 0, 0, 0]; an = [0, 0.78539816339744831, 1.5707963267948966]; "
                         "o = [0, 0.0005]; my_model = frSweepKeys(x, bar, ts, ps, an, o); }");
  Model expr = compileOk(bar +
                         "zero(x[1], a[1]) { zero = 0; }\n"
                         "turn(x[1], a[1]) { turn = 1.5707963267948966 * x[1]; }\n"
                         "my_model(x[2], a[1]) { array o[2]; o = [0, 0.0005]; "
                         "my_model = frSweep(x, bar, zero, zero, turn, 0, 1, o); }");
  for (auto p : std::vector<std::vector<double>>{{0.5, 0.5}, {0.7, 0.7}, {0.75, 0.72}, {0, 0.95}, {0, 1.05},
                                                 {0.95, 0}, {1.05, 0}, {0.5, -0.2}, {-0.5, -0.5}, {-0.4, 0.6}})
    EXPECT_NEAR(at(keys, p), at(expr, p), 1e-3) << p[0] << "," << p[1];
  // Translation keyframes with angles: the bar (turned by pi/2 at t = 1) ends up vertical at x1 = 3.
  Model moved = compileOk(bar +
                          "my_model(x[2], a[1]) { array ts[2], ps[4], an[2]; ts = [0, 1]; ps = [0, 0, 3, 0]; "
                          "an = [0, 1.5707963267948966]; my_model = frSweepKeys(x, bar, ts, ps, an); }");
  EXPECT_GT(at(moved, {3, 0.9}), 0);
  EXPECT_LT(at(moved, {3.5, 1.2}), 0);
  EXPECT_GT(at(moved, {-0.9, 0}), 0);  // t = 0: horizontal at the origin
}

// The paper examples in examples/extremum/ compile, and a point of each is right.
std::string exampleDir() {
  return std::string(FREP_SOURCE_DIR) + "/examples/extremum/";
}

Model compileExample(const std::string& name, const std::string& object = "") {
  CompileOptions o;
  o.object = object;
  CompileResult r = compileFile(exampleDir() + name, o);
  EXPECT_TRUE(r.ok) << name << "\n" << allDiagnostics(r);
  EXPECT_TRUE(r.diagnostics.empty()) << allDiagnostics(r);  // not even a warning
  return r.model;
}

TEST(FrExtremum, PaperExamples) {
  Model off = compileExample("minkowski_offset.hf");
  EXPECT_GT(at(off, {0.55, -0.5}), 0);   // the slot (0.12 wide) is filled by the 0.15 disc
  EXPECT_LT(at(off, {-0.45, -0.45}), 0);  // the hole (0.5 wide) shrinks but stays
  EXPECT_GT(at(off, {1.1, 0}), 0);
  EXPECT_LT(at(off, {1.2, 0}), 0);
  Model m0 = compileExample("minkowski_morph.hf", "morph_000");
  EXPECT_GT(at(m0, {0.9, 0}), 0);  // the cross's arm
  Model m1 = compileExample("minkowski_morph.hf", "morph_100");
  EXPECT_LT(at(m1, {0.9, 0}), 0);
  EXPECT_GT(at(m1, {0, 0.4}), 0);  // inside the triangle
  Model nc = compileExample("nc_machining.hf");
  EXPECT_LT(at(nc, {0, 0, 0.4}), 0);   // the groove at t = 0.5
  EXPECT_GT(at(nc, {0, 0.9, 0.4}), 0);  // block material beside it
  Model keys = compileExample("keyframe_sweep.hf");
  EXPECT_LT(at(keys, {0, -0.8, 0.35}), 0);   // the first pass's groove (tool centre at z = 0.3)
  EXPECT_GT(at(keys, {0, -0.8, 0.0}), 0);    // below the ball end (z >= 0.05 is cut)
  EXPECT_LT(at(keys, {0, 0.4, 0.35}), 0);    // the diagonal pass at x = 0: y = 0.4, z = 0.15
  EXPECT_GT(at(keys, {0, 0.95, 0.4}), 0);    // block material beside it
  Model p4 = compileExample("project_4d.hf");
  EXPECT_GT(at(p4, {1, 0, -0.8}), 0);  // t = 0: ball of radius 0.35 at (1, 0, -0.8)
  EXPECT_LT(at(p4, {0, 0, 0}), 0);
}

struct Err {
  std::string src;
  int line, column;
  std::string message;
};

void expectError(const Err& c) {
  CompileResult r = compile(c.src, "test.hf");
  ASSERT_FALSE(r.ok) << c.src;
  ASSERT_FALSE(r.diagnostics.empty());
  const Diagnostic& d = r.diagnostics.front();
  EXPECT_EQ(d.line, c.line) << d.format();
  EXPECT_EQ(d.column, c.column) << d.format();
  EXPECT_NE(d.message.find(c.message), std::string::npos) << d.format();
}

TEST(FrExtremum, ErrorsAtTheirPlace) {
  const std::string h = kBall3;  // line 1
  expectError({h + "m(x[3], a[1]) {\n  m = frMinkowski(x, ball, nothing);\n}", 3, 28,
               "nothing"});
  expectError({h + "d(x[2], a[1]) { d = 1 - x[1]^2; }\nm(x[3], a[1]) {\n  m = frMinkowski(x, ball, d);\n}",
               4, 28, "different dimensions"});
  expectError({h + "slab(x[3], a[1]) { slab = 1 - x[3]^2; }\nm(x[3], a[1]) {\n"
                   "  m = frMinkowski(x, ball, slab);\n}",
               4, 28, "object 'slab' is not bounded within ±1000"});
  expectError({h + "m(x[3], a[1]) {\n  m = frOffsetR(x, ball, x[1]);\n}", 3, 26,
               "the radius r must be a constant"});
  expectError({h + "m(x[3], a[1]) {\n  array o[2];\n  o = [x[1], 0];\n  m = frMinkowski(x, ball, ball, o);\n}",
               5, 34, "must be a constant known at compile time"});
  expectError({h + "m(x[3], a[1]) {\n  m = frProject(x, ball, 4);\n}", 3, 26,
               "not one of object 'ball''s x[1..3]"});
  expectError({h + "m(x[3], a[1]) {\n  m = frSweep(x, ball, ball, ball, ball, 0, 1);\n}", 3, 24,
               "must have x[1] (the time)"});
  expectError({h + "m(x[3], a[1]) {\n  m = frMinkowski(x, ball, later);\n}\nlater(x[3], a[1]) { later = 1; }",
               3, 28, "defined later"});
  expectError({h + "m(x[3], a[1]) {\n  v = 2;\n  m = frMinkowski(x, ball, v);\n}", 4, 28,
               "must be the name of an object"});
  expectError({h + "m(x[3], a[1]) {\n  array ts[3], ps[9];\n  ts = [0, 1, 1];\n  ps = [0, 0, 0, 1, 0, 0, 1, 1, 0];\n"
                   "  m = frSweepKeys(x, ball, ts, ps);\n}",
               6, 28, "keyframe times must increase strictly"});
  expectError({h + "m(x[3], a[1]) {\n  array ts[2], ps[5];\n  ts = [0, 1];\n  ps = [0, 0, 0, 1, 0];\n"
                   "  m = frSweepKeys(x, ball, ts, ps);\n}",
               6, 32, "must have 6 elements (3 coordinates for each of the 2 keyframes)"});
  expectError({h + "m(x[3], a[1]) {\n  array ts[2], ps[6], an[4];\n  ts = [0, 1];\n  ps = [0, 0, 0, 1, 0, 0];\n"
                   "  an = [0, 0, 0, 1];\n  m = frSweepKeys(x, ball, ts, ps, an);\n}",
               7, 36, "must be the angles (3 for each of the 2 keyframes: 6 elements) or the options"});
  expectError({h + "m(x[3], a[1]) {\n  array ts[2], v[3];\n  ts = [0, 1];\n  v = [0, 1, 2];\n"
                   "  m = frKeyframe(x[1], ts, v);\n}",
               6, 28, "must have 2 elements (one value per keyframe time)"});
  expectError({h + "m(x[3], a[1]) {\n  array ts[2], v[2];\n  ts = [0, x[1]];\n  v = [0, 1];\n"
                   "  m = frKeyframe(x[1], ts, v);\n}",
               6, 24, "must be a finite constant known at compile time"});
}

}  // namespace
}  // namespace frep::lang::testing
