// hf* convolution surfaces: closed forms checked against direct numerical integration of the
// Cauchy kernel 1/(1 + S^2 r^2)^2 (Gauss-Legendre, converged far below 1e-9 for these points).
#include "lang/hflib_test_util.h"
#include "lang/lang_test_util.h"

using namespace hftest;

namespace {

struct P3 {
  double x, y, z;
};
P3 lerp(P3 a, P3 b, double t) {
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)};
}
double dist2(P3 a, P3 b) {
  return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z);
}
double kernel(double S, double r2) { return 1.0 / ((1 + S * S * r2) * (1 + S * S * r2)); }

// Gauss-Legendre nodes and weights on [0, 1].
void gaussLegendre(int n, std::vector<double>& t, std::vector<double>& w) {
  t.assign(n, 0);
  w.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      double dx = p1 / dp;
      x -= dx;
      if (std::fabs(dx) < 1e-16) break;
    }
    t[i] = 0.5 * (1 - x);
    w[i] = 1.0 / ((1 - x * x) * dp * dp);  // = 2/((1-x^2)p'^2) scaled by 1/2 for [0,1]
  }
}

// Kernel integrated along a -> b, split into pieces for accuracy.
double lineIntegral(P3 x, P3 a, P3 b, double S) {
  std::vector<double> t, w;
  gaussLegendre(40, t, w);
  double len = std::sqrt(dist2(a, b)), sum = 0;
  const int pieces = 16;
  for (int p = 0; p < pieces; ++p)
    for (size_t i = 0; i < t.size(); ++i) {
      double u = (p + t[i]) / pieces;
      sum += w[i] / pieces * kernel(S, dist2(x, lerp(a, b, u)));
    }
  return sum * len;
}

// Kernel integrated over a triangle (collapsed square map, Jacobian 2A (1-u)).
double triangleIntegral(P3 x, P3 a, P3 b, P3 c, double S) {
  std::vector<double> t, w;
  gaussLegendre(60, t, w);
  P3 ab = {b.x - a.x, b.y - a.y, b.z - a.z}, ac = {c.x - a.x, c.y - a.y, c.z - a.z};
  P3 n = {ab.y * ac.z - ab.z * ac.y, ab.z * ac.x - ab.x * ac.z, ab.x * ac.y - ab.y * ac.x};
  double twoArea = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z), sum = 0;
  for (size_t i = 0; i < t.size(); ++i)
    for (size_t j = 0; j < t.size(); ++j) {
      double u = t[i], v = t[j] * (1 - u);
      P3 q = {a.x + u * ab.x + v * ac.x, a.y + u * ab.y + v * ac.y, a.z + u * ab.z + v * ac.z};
      sum += w[i] * w[j] * (1 - u) * kernel(S, dist2(x, q));
    }
  return sum * twoArea;
}

// Kernel integrated along an arc: radius r, opening theta (radians) in the local xy-plane,
// turned by beta about the unit axis u (right-hand rule), centred at c.
double arcIntegral(P3 x, P3 c, double r, double theta, P3 u, double beta, double S) {
  std::vector<double> t, w;
  gaussLegendre(40, t, w);
  const int pieces = 32;
  double sum = 0;
  for (int p = 0; p < pieces; ++p)
    for (size_t i = 0; i < t.size(); ++i) {
      double phi = theta * (p + t[i]) / pieces;
      P3 l = {r * std::cos(phi), r * std::sin(phi), 0};
      double cb = std::cos(beta), sb = std::sin(beta), ul = u.x * l.x + u.y * l.y + u.z * l.z;
      P3 uxl = {u.y * l.z - u.z * l.y, u.z * l.x - u.x * l.z, u.x * l.y - u.y * l.x};
      P3 q = {c.x + l.x * cb + uxl.x * sb + u.x * ul * (1 - cb),
              c.y + l.y * cb + uxl.y * sb + u.y * ul * (1 - cb),
              c.z + l.z * cb + uxl.z * sb + u.z * ul * (1 - cb)};
      sum += w[i] / pieces * kernel(S, dist2(x, q));
    }
  return sum * theta * r;
}

}  // namespace

TEST(HfLibConvolution, Point) {
  auto x = xyz();
  auto v = vals({0, 0, 0, 1, 0, 0}), S = vals({1, 2});
  Expr f = call("hfConvPoint", {arr(x), arr(v), arr(S), sc(0.5)});
  expectClose(at(f, 0, 1, 0), 1.0 / 4 + 1.0 / 81 - 0.5);
  expectClose(at(f, 0, 0, 0), 1.0 + 1.0 / 25 - 0.5);
  auto bad = vals({0, 0, 0, 1, 0});
  auto err = errorOf("hfConvPoint", {arr(x), arr(bad, "v"), arr(S, "s"), sc(0.5)});
  EXPECT_EQ(err.first, "hfConvPoint: array v must have 6 elements (3 per element of s) (got 5)");
  EXPECT_EQ(err.second, 1);
}

TEST(HfLibConvolution, LineMatchesNumericalIntegral) {
  auto x = xyz();
  auto b = vals({0, 0, 0, 1, 1, 1}), e = vals({2, 0, 0, 1, 3, 1}), S = vals({1.5, 0.7});
  Expr f = call("hfConvLine", {arr(x), arr(b), arr(e), arr(S), sc(0.25)});
  for (P3 p : {P3{0.5, 0.5, 0.2}, P3{-1, 2, 0.5}, P3{3, 0, 0}, P3{1, 0, 0}}) {
    double expect = lineIntegral(p, {0, 0, 0}, {2, 0, 0}, 1.5) +
                    lineIntegral(p, {1, 1, 1}, {1, 3, 1}, 0.7) - 0.25;
    expectClose(at(f, p.x, p.y, p.z), expect);
  }
  auto shortE = vals({2, 0, 0});
  auto err = errorOf("hfConvLine", {arr(x), arr(b), arr(shortE, "e"), arr(S, "s"), sc(0.25)});
  EXPECT_EQ(err.first, "hfConvLine: array e must have 6 elements (3 per element of s) (got 3)");
}

TEST(HfLibConvolution, CurveIsAPolyline) {
  auto x = xyz();
  auto v = vals({0, 0, 0, 1, 0, 0, 1, 2, 0}), S = vals({1, 2});
  Expr f = call("hfConvCurve", {arr(x), arr(v), arr(S), sc(0.1)});
  P3 p = {0.5, 1, 0.5};
  double expect =
      lineIntegral(p, {0, 0, 0}, {1, 0, 0}, 1) + lineIntegral(p, {1, 0, 0}, {1, 2, 0}, 2) - 0.1;
  expectClose(at(f, p.x, p.y, p.z), expect);
  auto err = errorOf("hfConvCurve", {arr(x), arr(S, "s"), arr(S, "s"), sc(0.1)});
  EXPECT_EQ(err.second, 1);
}

TEST(HfLibConvolution, TriangleMatchesNumericalIntegral) {
  auto x = xyz();
  auto v = vals({0, 0, 0, 2, 0, 0, 0, 1, 0.5}), S = vals({1.2});
  Expr f = call("hfConvTriangle", {arr(x), arr(v), arr(S), sc(0.3)});
  for (P3 p : {P3{0.5, 0.3, 0.6}, P3{3, -1, 1}, P3{-0.5, 0.5, -0.7}, P3{0.6, 0.2, 0.1}}) {
    // hfp's scale: S^3 times the integral over the area.
    double expect = std::pow(1.2, 3) * triangleIntegral(p, {0, 0, 0}, {2, 0, 0}, {0, 1, 0.5}, 1.2) - 0.3;
    expectClose(at(f, p.x, p.y, p.z), expect);
  }
  // Orientation does not matter.
  auto rev = vals({0, 1, 0.5, 2, 0, 0, 0, 0, 0});
  Expr g = call("hfConvTriangle", {arr(x), arr(rev), arr(S), sc(0.3)});
  expectClose(at(g, 3, -1, 1), at(f, 3, -1, 1));
}

// Values of hfp's own triangle formula (hfConvTriangle.c: edge-fan arctangents after sorting the
// longest edge first, re-evaluated outside the project), which differ from the area integral by
// the factor S^3.
TEST(HfLibConvolution, TriangleAgreesWithHfpsFormula) {
  auto x = xyz();
  auto v = vals({0, 0, 0, 2, 0.3, 0, 0.5, 1.7, 0.4});
  struct Case { P3 p; double S, hfp; };
  for (Case c : {Case{{0.3, 0.4, 0.8}, 0.7, 0.257805386220661}, Case{{1, 1, -0.5}, 1.3, 0.6785274084178758},
                 Case{{2, 2, 2}, 2.0, 0.018292663904778184}}) {
    auto S = vals({c.S});
    Expr f = call("hfConvTriangle", {arr(x), arr(v), arr(S), sc(0)});
    expectClose(at(f, c.p.x, c.p.y, c.p.z), c.hfp);
  }
}

TEST(HfLibConvolution, MeshSumsIndexedTriangles) {
  auto x = xyz();
  auto v = vals({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1}), tri = vals({1, 2, 3, 2, 4, 3}),
       S = vals({1, 2});
  Expr f = call("hfConvMesh", {arr(x), arr(v), arr(tri), arr(S), sc(0.2)});
  P3 p = {0.2, 0.4, 0.9};
  double expect = triangleIntegral(p, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1) +
                  8 * triangleIntegral(p, {1, 0, 0}, {1, 1, 1}, {0, 1, 0}, 2) - 0.2;
  expectClose(at(f, p.x, p.y, p.z), expect);
  auto badTri = vals({1, 2, 5, 2, 4, 3});
  auto err = errorOf("hfConvMesh", {arr(x), arr(v), arr(badTri), arr(S), sc(0.2)});
  EXPECT_EQ(err.first, "hfConvMesh: triangle index 5 out of range 1..4");
  EXPECT_EQ(err.second, 2);
}

TEST(HfLibConvolution, ArcMatchesNumericalIntegral) {
  auto x = xyz();
  // Arc 1: 270 degrees, radius 2, centre (1,0,0), turned 90 degrees about x (into the xz-plane).
  // Arc 2: full circle of radius 1 at (0,0,3), not turned.
  auto c = vals({1, 0, 0, 0, 0, 3}), rad = vals({2, 1}), th = vals({270, 360}),
       ax = vals({1, 0, 0, 0, 1, 0}), ang = vals({90, 0}), S = vals({1.1, 0.8});
  Expr f = call("hfConvArc", {arr(x), arr(c), arr(rad), arr(th), arr(ax), arr(ang), arr(S), sc(0.3)});
  // hfp's scale and quirks: the integral over the angle (arc length integral / r), degrees with
  // pi = 3.141592, axis components and angle + 1e-6.
  const double deg = 3.141592 / 180, e = 1e-6;
  auto unit = [](P3 u) {
    double l = std::sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
    return P3{u.x / l, u.y / l, u.z / l};
  };
  auto arc1 = [&](P3 p) {
    return arcIntegral(p, {1, 0, 0}, 2, 270 * deg, unit({1 + e, e, e}), (90 + e) * deg, 1.1) / 2;
  };
  for (P3 p : {P3{1, 0.5, 1.5}, P3{-1, -0.5, 0.2}, P3{0.3, 0.2, 3.1}, P3{2.5, 1, -1}}) {
    double expect = arc1(p) + arcIntegral(p, {0, 0, 3}, 1, 360 * deg, unit({e, 1 + e, e}), e * deg, 0.8) - 0.3;
    expectClose(at(f, p.x, p.y, p.z), expect);
  }
  // On the axis of the full circle the integrand is constant: 2 pi / (1 + S^2 (r^2 + h^2))^2.
  double onAxis = 360 * deg / std::pow(1 + 0.64 * (1 + 4), 2);
  expectClose(at(f, 0, 0, 5), onAxis + arc1({0, 0, 5}) - 0.3);
  auto shortTheta = vals({270});
  auto err = errorOf("hfConvArc", {arr(x), arr(c), arr(rad), arr(shortTheta, "th"), arr(ax),
                                   arr(ang), arr(S, "s"), sc(0.3)});
  EXPECT_EQ(err.first, "hfConvArc: array th must have 2 elements (one per element of s) (got 1)");
  EXPECT_EQ(err.second, 3);
}

// hfConvLineR: min(1, sum of segment fields) - T, S = 1/R if R < 1 else 1, T the field of the
// last segment at distance R from its start point, perpendicular to it. Expected values use the
// numerical line integral above.
TEST(HfLibConvolution, LineRHandPoints) {
  auto x = xyz();
  // One segment, R < 1 so S = 1/R = 2.
  auto b = vals({0, 0, 0}), e = vals({2, 0, 0});
  Expr f = call("hfConvLineR", {arr(x), arr(b), arr(e), sc(0.5)});
  double T = lineIntegral({0, 0.5, 0}, {0, 0, 0}, {2, 0, 0}, 2);
  for (P3 p : {P3{1, 0.7, 0.2}, P3{-0.5, 0.3, 0}, P3{2.5, 1, -1}}) {
    double expect = std::min(1.0, lineIntegral(p, {0, 0, 0}, {2, 0, 0}, 2)) - T;
    expectClose(at(f, p.x, p.y, p.z), expect);
  }
  // R >= 1 so S = 1; two segments, T from the last one (length 3).
  auto b2 = vals({0, 0, 0, 0, 0, 1}), e2 = vals({2, 0, 0, 0, 3, 1});
  Expr g = call("hfConvLineR", {arr(x), arr(b2), arr(e2), sc(1.5)});
  double T2 = lineIntegral({1.5, 0, 1}, {0, 0, 1}, {0, 3, 1}, 1);
  for (P3 p : {P3{1, 2, 3}, P3{4, 0.5, -1}, P3{-2, -2, 2}}) {
    double sum = lineIntegral(p, {0, 0, 0}, {2, 0, 0}, 1) + lineIntegral(p, {0, 0, 1}, {0, 3, 1}, 1);
    expectClose(at(g, p.x, p.y, p.z), std::min(1.0, sum) - T2);
  }
  // The sum is capped at 1: on the axis of a long segment the field is near pi/2 (S = 1).
  auto bl = vals({-10, 0, 0}), el = vals({10, 0, 0});
  Expr h = call("hfConvLineR", {arr(x), arr(bl), arr(el), sc(2.0)});
  ASSERT_GT(lineIntegral({0, 0.1, 0}, {-10, 0, 0}, {10, 0, 0}, 1), 1.0);
  expectClose(at(h, 0, 0.1, 0), 1.0 - lineIntegral({-10, 2, 0}, {-10, 0, 0}, {10, 0, 0}, 1));
}

TEST(HfLibConvolution, LineRSurfaceAtDistanceRFromTheStartPoint) {
  auto x = xyz();
  auto b = vals({1, 1, 0}), e = vals({1, 1, 4});
  for (double R : {0.4, 1.0, 2.5}) {
    Expr f = call("hfConvLineR", {arr(x), arr(b), arr(e), sc(R)});
    // The plane through b perpendicular to the segment: zero exactly at distance R, inside
    // (> 0) nearer, outside farther.
    for (double phi : {0.0, 1.0, 2.5}) {
      double cx = std::cos(phi), cy = std::sin(phi);
      EXPECT_NEAR(at(f, 1 + R * cx, 1 + R * cy, 0), 0.0, 1e-12);
      EXPECT_GT(at(f, 1 + 0.9 * R * cx, 1 + 0.9 * R * cy, 0), 0.0);
      EXPECT_LT(at(f, 1 + 1.1 * R * cx, 1 + 1.1 * R * cy, 0), 0.0);
    }
    // hfp's threshold is taken at the start point, not the middle: on the midpoint's
    // perpendicular the field at distance R exceeds it, so the surface lies farther out there.
    EXPECT_GT(at(f, 1 + R, 1, 2), 0.0);
  }
  auto bad = vals({0, 0, 0, 1});
  auto err = errorOf("hfConvLineR", {arr(x), arr(bad, "b"), arr(bad, "e"), sc(1.0)});
  EXPECT_EQ(err.first, "hfConvLineR: array e size must be a positive multiple of 3 (got 4)");
  EXPECT_EQ(err.second, 2);
  auto e6 = vals({1, 0, 0, 2, 0, 0});
  err = errorOf("hfConvLineR", {arr(x), arr(b, "b"), arr(e6, "e"), sc(1.0)});
  EXPECT_EQ(err.first, "hfConvLineR: array b must have 6 elements (as many as e) (got 3)");
  EXPECT_EQ(err.second, 1);
}

TEST(HfLibConvolution, LineRFromHyperFunSource) {
  const char* src = R"(my_model(x[3], a[1]) {
    array b[3], e[3];
    b = [0, 0, 0]; e = [2, 0, 0];
    my_model = hfConvLineR(x, b, e, 0.5);
  })";
  frep::lang::Model m = frep::lang::testing::compileOk(src);
  double T = lineIntegral({0, 0.5, 0}, {0, 0, 0}, {2, 0, 0}, 2);
  expectClose(frep::lang::testing::evalModel(m, {1, 0.7, 0.2}),
              std::min(1.0, lineIntegral({1, 0.7, 0.2}, {0, 0, 0}, {2, 0, 0}, 2)) - T);
  EXPECT_NEAR(frep::lang::testing::evalModel(m, {0, 0, 0.5}), 0.0, 1e-12);
}

namespace {

// The plane is the limit of a growing triangle: hfConvTriangle over a triangle reaching 1e5
// around the foot of the point (the tail beyond is below pi / (S R^2) ~ 1e-10).
TEST(HfLibConvolution, PlaneIsTheLimitOfAGrowingTriangle) {
  auto x = xyz();
  auto p = vals({0.3, -0.2, 0.5}), n = vals({0, 0, 2}), S = vals({0.9});
  Expr f = call("frConvPlane", {arr(x), arr(p), arr(n), arr(S), sc(0.1)});
  auto big = vals({-1e5, -1e5, 0.5, 3e5, -1e5, 0.5, -1e5, 3e5, 0.5});
  Expr g = call("hfConvTriangle", {arr(x), arr(big), arr(S), sc(0.1)});
  for (P3 q : {P3{0, 0, 0.5}, P3{1, 2, 1.7}, P3{-3, 0.4, -0.8}}) {
    double h = q.z - 0.5;
    EXPECT_NEAR(at(f, q.x, q.y, q.z), kPi * 0.9 / (1 + 0.81 * h * h) - 0.1, 1e-12);
    EXPECT_NEAR(at(f, q.x, q.y, q.z), at(g, q.x, q.y, q.z), 1e-7);
  }
  auto zero = vals({0, 0, 0});
  auto err = errorOf("frConvPlane", {arr(x), arr(p), arr(zero, "n"), arr(S), sc(0.1)});
  EXPECT_EQ(err.first, "frConvPlane: normal 1 of n is zero");
}

}  // namespace
