// hf* distance primitives (signed Euclidean distance, + inside), blends and SARDF operations.
#include <array>
#include <memory>

#include "lang/hflib_test_util.h"
#include "lang/lang_test_util.h"

using namespace hftest;

TEST(HfLibDistance, Cones) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  Expr z = call("hfDConeZ", {arr(x), arr(c), sc(1.0)});  // half-angle 45 degrees
  expectClose(at(z, 1, 0, 1), 0.0);
  expectClose(at(z, 0, 0, -2), std::sqrt(2.0));  // on the axis: |h| sin 45
  expectClose(at(z, 3, 4, 0), -5 * std::sqrt(0.5));
  Expr xc = call("hfDConeX", {arr(x), arr(c), sc(2.0)});
  double t = std::atan(2.0);
  expectClose(at(xc, 3, 1, 2), 3 * std::sin(t) - std::sqrt(5.0) * std::cos(t));
  Expr yc = call("hfDConeY", {arr(x), arr(c), sc(0.5)});
  t = std::atan(0.5);
  expectClose(at(yc, 1, -4, 0), 4 * std::sin(t) - std::cos(t));
}

TEST(HfLibDistance, Tori) {
  auto x = xyz();
  auto c = vals({1, 0, 0});
  Expr z = call("hfDTorusZ", {arr(x), arr(c), sc(3.0), sc(1.0)});
  expectClose(at(z, 4, 0, 0), 1.0);
  expectClose(at(z, 6, 0, 0), -1.0);
  expectClose(at(z, 1, 0, 0), -2.0);
  expectClose(at(z, 1, 3, 2), -1.0);
  Expr xt = call("hfDTorusX", {arr(x), arr(c), sc(3.0), sc(1.0)});
  expectClose(at(xt, 1, 0, 3.5), 0.5);
  Expr yt = call("hfDTorusY", {arr(x), arr(c), sc(2.0), sc(0.5)});
  expectClose(at(yt, 1 + 3, 4, 0), 0.5 - std::sqrt(1.0 + 16.0));
}

TEST(HfLibDistance, Cylinder) {
  auto x = xyz();
  auto c = vals({0, 0, 0}), u = vals({0, 0, 2});
  Expr f = call("hfDCylinder", {arr(x), arr(c), arr(u), sc(1.0)});
  expectClose(at(f, 3, 4, 7), -4.0);
  expectClose(at(f, 0.5, 0, -9), 0.5);
  auto c2 = vals({1, 1, 0}), u2 = vals({1, 1, 0});
  Expr g = call("hfDCylinder", {arr(x), arr(c2), arr(u2), sc(2.0)});
  expectClose(at(g, 2, 0, 1), 2.0 - std::sqrt(2.0 + 1.0));  // (1,-1,1) off a diagonal line
}

TEST(HfLibDistance, EllipsoidSphereCase) {
  auto x = xyz();
  auto c = vals({1, 1, 1});
  Expr f = call("hfDEllipsoid", {arr(x), arr(c), sc(2.0), sc(2.0), sc(2.0)});
  expectClose(at(f, 1, 1, 4), -1.0);
  expectClose(at(f, 2, 2, 2), 2.0 - std::sqrt(3.0));
  expectClose(at(f, 1, 1, 1), 2.0);
}

TEST(HfLibDistance, EllipsoidAxesAndDegenerateInterior) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  Expr f = call("hfDEllipsoid", {arr(x), arr(c), sc(3.0), sc(2.0), sc(1.0)});
  expectClose(at(f, 5, 0, 0), -2.0);
  expectClose(at(f, 0, 0, 3), -2.0);
  expectClose(at(f, 0, 0, 0.5), 0.5);
  expectClose(at(f, 0, 0, 0), 1.0);  // nearest along the smallest axis
  // Inside on the major axis, beyond the evolute: nearest point (2.25, 0, ±sqrt(0.4375)).
  expectClose(at(f, 2, 0, 0), std::sqrt(0.5));
  expectClose(at(f, 3, 0, 0), 0.0);
}

TEST(HfLibDistance, EllipsoidGeneralPointAgainstBisection) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  double a[3] = {3, 2, 1}, p[3] = {2.5, 1.5, 0.75};
  Expr f = call("hfDEllipsoid", {arr(x), arr(c), sc(a[0]), sc(a[1]), sc(a[2])});
  // Independent reference: bisection on G(s) = sum (a_i p_i / (s + a_i^2 - 1))^2 - 1, s > 0.
  auto G = [&](double s) {
    double g = -1;
    for (int i = 0; i < 3; ++i) g += std::pow(a[i] * p[i] / (s + a[i] * a[i] - 1), 2);
    return g;
  };
  double lo = 0, hi = 100;
  for (int k = 0; k < 200; ++k) (G(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  double s = 0.5 * (lo + hi), d2 = 0;
  for (int i = 0; i < 3; ++i) d2 += std::pow(p[i] - a[i] * a[i] * p[i] / (s + a[i] * a[i] - 1), 2);
  expectClose(at(f, p[0], p[1], p[2]), -std::sqrt(d2));  // (2.5/3)^2 + (1.5/2)^2 + .75^2 > 1
}

TEST(HfLibDistance, RFunctionBlends) {
  double f1 = 1, f2 = 2, a0 = 1, a1 = 1, a2 = 2;
  double disp = a0 / (1 + (f1 / a1) * (f1 / a1) + (f2 / a2) * (f2 / a2));
  Expr u = call("hfBlendUni", {sc(f1), sc(f2), sc(a0), sc(a1), sc(a2)});
  expectClose(at(u), f1 + f2 + std::sqrt(5.0) + disp);
  Expr i = call("hfBlendInt", {sc(f1), sc(f2), sc(a0), sc(a1), sc(a2)});
  expectClose(at(i), f1 + f2 - std::sqrt(5.0) + disp);
  Expr xs = call("hfBlendInt", {sc(Expr::x(0)), sc(-3.0), sc(0.5), sc(2.0), sc(3.0)});
  double x0 = 4;
  expectClose(at(xs, x0), x0 - 3 - 5 + 0.5 / (1 + 4 + 1));
}

TEST(HfLibDistance, DistanceBlends) {
  Expr u = call("hfDBlendUni", {sc(Expr::x(0)), sc(Expr::x(1)), sc(1.0)});
  expectClose(at(u, 0, 0), 1 - std::sqrt(2.0) / 2);
  expectClose(at(u, 0, 3), 3.0);  // |f2 - f1| > r: max
  expectClose(at(u, -2, 0.5), 0.5);
  // |f2 - f1| = 0.5: d = r + (f1 + f2 - sqrt(2 r^2 - 0.25)) / 2
  expectClose(at(u, 0.5, 1), 1 + (1.5 - std::sqrt(1.75)) / 2);
  expectClose(at(u, 0, 1), 1.0);  // boundary of the fillet meets max
  Expr i = call("hfDBlendInt", {sc(Expr::x(0)), sc(Expr::x(1)), sc(2.0)});
  expectClose(at(i, 0, 0), -2 + std::sqrt(8.0) / 2);
  expectClose(at(i, 1, -4), -4.0);
  expectClose(at(i, 1, 0), -2 + (1 + std::sqrt(7.0)) / 2);
}

// SARDF set operations (Fayolle, Pasko, Schmitt 2008). Expected values come from the geometry
// of the level curves: the level-d curve of the union is max(x, y) = d with its corner replaced
// by a circle tangent to x = d and y = d; a point built on that circle has value d.
namespace {

struct Tape2 {
  frep::TapePtr tape;
  frep::PointEvaluator ev;
  explicit Tape2(const Expr& e) : tape(frep::Tape::compile(e, 3)) {}
  double operator()(double f1, double f2) {
    double p[3] = {f1, f2, 0};
    return ev.eval(*tape, p);
  }
};

Expr sardfCall(const char* name, double R, double alpha) {
  return call(name, {sc(Expr::x(0)), sc(Expr::x(1)), sc(R), sc(alpha)});
}

}  // namespace

TEST(HfLibDistance, SardfUnionHandPoints) {
  const double R = 1, alpha = kPi / 6, t = std::tan(alpha);
  Expr u = sardfCall("hfDUni", R, alpha);
  // Opposite signs and axes: max.
  expectClose(at(u, -1, 2), 2.0);
  expectClose(at(u, 3, -0.5), 3.0);
  expectClose(at(u, 0, -2), 0.0);
  // Quadrant I, inside the wedge t < x/y < 1/t: level 2 is the circle centred (2t, 2t) of
  // radius 2(1 - t).
  double d = 2, th = 0.4;
  expectClose(at(u, t * d + (1 - t) * d * std::cos(th), t * d + (1 - t) * d * std::sin(th)), d);
  // On the diagonal x = y = 1: 1 = t d + (1 - t) d / sqrt 2.
  expectClose(at(u, 1, 1), 1 / (t + (1 - t) / std::sqrt(2.0)));
  // Quadrant I outside the wedge: max.
  expectClose(at(u, 3, 0.5), 3.0);
  expectClose(at(u, 0.2, 2), 2.0);
  // alpha = pi/8 makes the quadratic's leading coefficient t^2 + 2t - 1 vanish.
  double t8 = std::tan(kPi / 8);
  expectClose(at(sardfCall("hfDUni", R, kPi / 8), 1, 1), 1 / (t8 + (1 - t8) / std::sqrt(2.0)));
  // alpha = 0: the whole quadrant is the wedge and the level curves are quarter circles.
  expectClose(at(sardfCall("hfDUni", R, 0.0), 3, 4), 5.0);
  // Quadrant III inside the level -R curve: level -m^2 has radius rho = 2 sqrt(R) m - m^2 and
  // centre (-2 sqrt(R) m, -2 sqrt(R) m).
  for (double th3 : {kPi / 4, 0.2, 1.3}) {
    double m = 0.5, rho = 2 * m - m * m, c = -2 * m;
    expectClose(at(u, c + rho * std::cos(th3), c + rho * std::sin(th3)), -m * m);
  }
  {
    double R2 = 2, s = std::sqrt(R2), m = 0.8, rho = 2 * s * m - m * m, c = -2 * s * m;
    Expr u2 = sardfCall("hfDUni", R2, alpha);
    expectClose(at(u2, c + rho * std::cos(1.0), c + rho * std::sin(1.0)), -m * m);
  }
  // Quadrant III, straight part of a level curve (outside the parabolas): max.
  expectClose(at(u, -0.2, -3), -0.2);
  // Level -R itself: circle of radius R centred (-2R, -2R).
  expectClose(at(u, -2 + std::cos(0.7), -2 + std::sin(0.7)), -1.0);
  // Beyond level -R: the fixed fillet of radius R centred (d - R, d - R); max off the strip.
  expectClose(at(u, -4 + std::cos(kPi / 3), -4 + std::sin(kPi / 3)), -3.0);
  expectClose(at(u, -10, -3), -3.0);
}

TEST(HfLibDistance, SardfIntersectionAndSubtractionHandPoints) {
  const double R = 1, alpha = kPi / 6, t = std::tan(alpha);
  Expr i = sardfCall("hfDInt", R, alpha);
  expectClose(at(i, -1, 2), -1.0);
  expectClose(at(i, 3, -0.5), -0.5);
  // Quadrant I inside the level R curve: level m^2 is the arc of radius 2m - m^2 centred (2m, 2m)
  // on the side of the origin.
  double m = 0.5, rho = 2 * m - m * m;
  double px = 2 * m - rho * std::cos(0.5), py = 2 * m - rho * std::sin(0.5);
  expectClose(at(i, px, py), m * m);
  // Beyond level R: the fillet of radius R centred (d + R, d + R).
  expectClose(at(i, 4 - std::cos(1.2), 4 - std::sin(1.2)), 3.0);
  expectClose(at(i, 10, 3), 3.0);
  expectClose(at(i, 0.2, 3), 0.2);
  // Quadrant III, wedge: level -2 is the circle centred (-2t, -2t) of radius 2(1 - t).
  double d = 2, th = 1.1;
  expectClose(at(i, -(t * d + (1 - t) * d * std::cos(th)), -(t * d + (1 - t) * d * std::sin(th))),
              -d);
  expectClose(at(i, -3, -0.5), -3.0);
  // Subtraction is the intersection with -f2.
  Expr s = sardfCall("hfDSub", R, alpha);
  expectClose(at(s, px, -py), m * m);
  expectClose(at(s, -1, -2), -1.0);
  expectClose(at(s, 3, 0.5), -0.5);
  expectClose(at(s, 4 - std::cos(1.2), -(4 - std::sin(1.2))), 3.0);
}

TEST(HfLibDistance, SardfSignsBoundsAndMaxMinAwayFromBlend) {
  for (double R : {0.5, 1.0, 2.0})
    for (double alpha : {0.0, kPi / 12, kPi / 8, kPi / 6}) {
      Tape2 u(sardfCall("hfDUni", R, alpha)), in(sardfCall("hfDInt", R, alpha)),
          sub(sardfCall("hfDSub", R, alpha));
      double t = std::tan(alpha);
      for (double x = -5.03; x < 5; x += 0.173)
        for (double y = -5.01; y < 5; y += 0.191) {
          double mx = std::max(x, y), mn = std::min(x, y), sm = std::min(x, -y);
          double vu = u(x, y), vi = in(x, y), vs = sub(x, y);
          ASSERT_TRUE(std::isfinite(vu) && std::isfinite(vi) && std::isfinite(vs)) << x << " " << y;
          EXPECT_EQ(vu > 0, mx > 0) << x << " " << y;
          EXPECT_EQ(vi > 0, mn > 0) << x << " " << y;
          EXPECT_EQ(vs > 0, sm > 0) << x << " " << y;
          // The rounding only cuts corners: union >= max, intersection <= min.
          EXPECT_GE(vu, mx - 1e-12);
          EXPECT_LE(vi, mn + 1e-12);
          // Away from the blending regions the operations are exactly max / min.
          bool q1 = x > 0 && y > 0, q3 = x < 0 && y < 0;
          bool uBlend = (q1 && x / y < 1 / t && x / y > t) || (q3 && std::fabs(x - y) <= R);
          bool iBlend = (q3 && x / y < 1 / t && x / y > t) || (q1 && std::fabs(x - y) <= R);
          if (!uBlend) {
            EXPECT_EQ(vu, mx) << x << " " << y;
          }
          if (!iBlend) {
            EXPECT_EQ(vi, mn) << x << " " << y;
          }
        }
    }
}

TEST(HfLibDistance, SardfIsC1AcrossEveryPieceBoundary) {
  const double R = 1, alpha = kPi / 6, t = std::tan(alpha);
  Tape2 u(sardfCall("hfDUni", R, alpha)), in(sardfCall("hfDInt", R, alpha));
  const double h = 1e-7, delta = 1e-5;
  auto grad = [&](Tape2& f, double x, double y) {
    return std::array<double, 2>{(f(x + h, y) - f(x - h, y)) / (2 * h),
                                 (f(x, y + h) - f(x, y - h)) / (2 * h)};
  };
  // Each boundary point p with a direction n across the boundary; sign -1 checks the dual.
  struct Cross {
    double x, y, nx, ny;
  };
  std::vector<Cross> cuts = {
      {2 / t, 2, 1, -1},                                        // wedge ray x/y = 1/t
      {0.7 * t, 0.7, 1, -1},                                    // wedge ray x/y = t
      {-0.5, -0.0625, 0, 1},                                    // parabola y = -x^2/(4R)
      {-1.5 * 1.5 / 4, -1.5, 1, 0},                             // parabola x = -y^2/(4R)
      {-2 + std::cos(0.7), -2 + std::sin(0.7), std::cos(0.7), std::sin(0.7)},  // level -R arc
      {-1, -3.5, 1, 0},                                         // x = -R below the arc
      {-3.5, -4.5, 1, -1},                                      // fillet strip |x - y| = R
      {-0.3, 0, 0, 1},                                          // axis y = 0
      {2, 0, 0, 1},                                             // axis y = 0, x > 0
  };
  for (const Cross& c : cuts)
    for (int dual = 0; dual < 2; ++dual) {
      Tape2& f = dual ? in : u;
      double sx = dual ? -c.x : c.x, sy = dual ? -c.y : c.y;
      auto ga = grad(f, sx - delta * c.nx, sy - delta * c.ny);
      auto gb = grad(f, sx + delta * c.nx, sy + delta * c.ny);
      EXPECT_NEAR(ga[0], gb[0], 1e-3) << c.x << " " << c.y << " dual " << dual;
      EXPECT_NEAR(ga[1], gb[1], 1e-3) << c.x << " " << c.y << " dual " << dual;
      EXPECT_NEAR(f(sx - delta * c.nx, sy - delta * c.ny), f(sx + delta * c.nx, sy + delta * c.ny),
                  1e-4);
    }
  // Sanity: the same check sees max's kink on the diagonal.
  Tape2 mx(max(Expr::x(0), Expr::x(1)));
  auto ga = grad(mx, 1 - delta, 1 + delta), gb = grad(mx, 1 + delta, 1 - delta);
  EXPECT_GT(std::fabs(ga[0] - gb[0]), 0.5);
}

TEST(HfLibDistance, SardfArcRootAgainstBisection) {
  // Points inside the level -R curve between the parabolas, at several scales: the value -m^2
  // where the arc of radius 2 sqrt(R) m - m^2 centred (-2 sqrt(R) m, -2 sqrt(R) m) passes
  // through the point, found by bisection on m (independent of the Newton iteration).
  const double R = 1.7, s = std::sqrt(R);
  Tape2 u(sardfCall("hfDUni", R, 0.3));
  int checked = 0;
  for (double scale : {1.0, 1e-3, 1e-8, 1e-20})
    for (double a = 0.05; a < 1; a += 0.05)
      for (double b = 0.05; b < 1; b += 0.05) {
        double x = -a * scale, y = -b * scale;
        if (!(x <= -y * y / (4 * R) && y <= -x * x / (4 * R))) continue;
        if (!(x >= -R || y >= -R)) continue;
        double lo = std::max(-x, -y) / (2 * s), hi = s;
        for (int k = 0; k < 200; ++k) {
          double m = 0.5 * (lo + hi), cu = x + 2 * s * m, cv = y + 2 * s * m;
          (2 * s * m - m * m - std::sqrt(cu * cu + cv * cv) > 0 ? lo : hi) = m;
        }
        double m = 0.5 * (lo + hi);
        EXPECT_NEAR(u(x, y), -m * m, 1e-12 * m * m) << x << " " << y;
        ++checked;
      }
  EXPECT_GT(checked, 400);
}

TEST(HfLibDistance, SardfFromHyperFunSource) {
  // Two balls as distances (radius - |p - c|), united, intersected and subtracted by name.
  const char* src = R"(my_model(x[3], a[1]) {
    array c1[3], c2[3];
    c1 = [0, 0, 0]; c2 = [1.5, 0, 0];
    d1 = 1 - sqrt((x[1]-c1[1])^2 + (x[2]-c1[2])^2 + (x[3]-c1[3])^2);
    d2 = 1 - sqrt((x[1]-c2[1])^2 + (x[2]-c2[2])^2 + (x[3]-c2[3])^2);
    my_model = hfdUNI(d1, d2, 0.5, 0.4) + 10 * hfDInt(d1, d2, 0.5, 0.4) + 100 * hfDSub(d1, d2, 0.5, 0.4);
  })";
  frep::lang::Model m = frep::lang::testing::compileOk(src);
  Expr u = sardfCall("hfDUni", 0.5, 0.4), i = sardfCall("hfDInt", 0.5, 0.4),
       s = sardfCall("hfDSub", 0.5, 0.4);
  for (double px : {-0.5, 0.3, 0.75, 1.2, 3.0}) {
    double d1 = 1 - std::fabs(px), d2 = 1 - std::fabs(px - 1.5);
    expectClose(frep::lang::testing::evalModel(m, {px, 0, 0}),
                at(u, d1, d2) + 10 * at(i, d1, d2) + 100 * at(s, d1, d2));
  }
}
