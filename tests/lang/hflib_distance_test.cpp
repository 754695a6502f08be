// hf* distance primitives (signed Euclidean distance, + inside) and blends.
#include "lang/hflib_test_util.h"

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
