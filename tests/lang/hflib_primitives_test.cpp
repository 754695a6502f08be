// hf* algebraic primitives at hand-computed points (expected values from the documented
// formulas in plain doubles).
#include "lang/hflib_test_util.h"

using namespace hftest;

TEST(HfLibPrimitives, Sphere) {
  auto x = xyz();
  auto c = vals({1, 2, 3});
  Expr f = call("hfSphere", {arr(x), arr(c), sc(2.0)});
  expectClose(at(f, 1, 2, 3), 4.0);
  expectClose(at(f, 2, 3, 4), 1.0);
  expectClose(at(f, 3, 2, 3), 0.0);
  expectClose(at(f, -1, 0.5, 3.25), 4.0 - 4.0 - 2.25 - 0.0625);
}

TEST(HfLibPrimitives, SphereIsCaseInsensitiveAndSymbolic) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  Expr f = call("HFSPHERE", {arr(x), arr(c), sc(Expr::param(0))});
  EXPECT_FALSE(f.isConst());
  Expr bound = frep::bindParams(f, {Expr(3.0)});
  expectClose(at(bound, 1, 1, 1), 6.0);
}

TEST(HfLibPrimitives, Ellipsoid) {
  auto x = xyz();
  auto c = vals({0, 1, 0});
  Expr f = call("hfEllipsoid", {arr(x), arr(c), sc(2.0), sc(3.0), sc(4.0)});
  expectClose(at(f, 1, 2, 1), 1 - 0.25 - 1.0 / 9 - 1.0 / 16);
  expectClose(at(f, 2, 1, 0), 0.0);
  expectClose(at(f, 0, 1, 8), -3.0);
}

TEST(HfLibPrimitives, Cylinders) {
  auto x = xyz();
  auto c = vals({1, 0, 0});
  // p = (2, 1, 2) at the point (3, 1, 2)
  expectClose(at(call("hfCylinderX", {arr(x), arr(c), sc(2.0)}), 3, 1, 2), 4 - 1 - 4);
  expectClose(at(call("hfCylinderY", {arr(x), arr(c), sc(2.0)}), 3, 1, 2), 4 - 4 - 4);
  expectClose(at(call("hfCylinderZ", {arr(x), arr(c), sc(2.0)}), 3, 1, 2), 4 - 4 - 1);
  expectClose(at(call("hfCylinderZ", {arr(x), arr(c), sc(2.0)}), 1, 0, 100), 4.0);
}

TEST(HfLibPrimitives, EllipticCylinders) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  double px = 1, py = 2, pz = 3, a = 2, b = 4;
  auto ec = [&](const char* n) { return call(n, {arr(x), arr(c), sc(a), sc(b)}); };
  expectClose(at(ec("hfEllCylX"), px, py, pz), 1 - (py / a) * (py / a) - (pz / b) * (pz / b));
  expectClose(at(ec("hfEllCylY"), px, py, pz), 1 - (px / a) * (px / a) - (pz / b) * (pz / b));
  expectClose(at(ec("hfEllCylZ"), px, py, pz), 1 - (px / a) * (px / a) - (py / b) * (py / b));
  expectClose(at(ec("hfEllCylZ"), 2, 0, 7), 0.0);
}

TEST(HfLibPrimitives, Tori) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  auto torus = [&](const char* n) { return call(n, {arr(x), arr(c), sc(3.0), sc(1.0)}); };
  // Tube centre: r0^2; tube surface: 0; torus centre: r0^2 - R^2.
  expectClose(at(torus("hfTorusZ"), 3, 0, 0), 1.0);
  expectClose(at(torus("hfTorusZ"), 0, 4, 0), 0.0);
  expectClose(at(torus("hfTorusZ"), 0, 0, 0), 1.0 - 9.0);
  expectClose(at(torus("hfTorusX"), 0, 0, 3), 1.0);
  expectClose(at(torus("hfTorusX"), 3, 0, 0), 1.0 - 9.0 - 9.0);
  expectClose(at(torus("hfTorusY"), 2, 1, 0), 1.0 - 5.0 - 9.0 + 2 * 3 * 2.0);
}

TEST(HfLibPrimitives, Block) {
  auto x = xyz();
  auto v = vals({0, 0, 0});
  Expr f = call("hfBlock", {arr(x), arr(v), sc(2.0), sc(4.0), sc(6.0)});
  auto rint = [](double a, double b) { return a + b - std::sqrt(a * a + b * b); };
  // slabs at (1, 2, 3): sx = 1*1, sy = 2*2, sz = 3*3
  expectClose(at(f, 1, 2, 3), rint(rint(1, 4), 9));
  // outside in x: sx = (3)(2 - 3) = -3
  expectClose(at(f, 3, 2, 3), rint(rint(-3, 4), 9));
  expectClose(at(f, 0, 1, 1), rint(rint(0, 3), 5));
  auto err = errorOf("hfBlock", {arr(x), arr(v), sc(2.0), sc(-1.0), sc(6.0)});
  EXPECT_EQ(err.second, 3);
}

TEST(HfLibPrimitives, Cones) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  auto cone = [&](const char* n) { return call(n, {arr(x), arr(c), sc(2.0)}); };
  expectClose(at(cone("hfConeX"), 2, 1, 1), 4 - 0.25 - 0.25);
  expectClose(at(cone("hfConeY"), 2, 1, 1), 1 - 1 - 0.25);
  expectClose(at(cone("hfConeZ"), 2, 2, 1), 1 - 1 - 1);
  auto ell = [&](const char* n) { return call(n, {arr(x), arr(c), sc(2.0), sc(4.0)}); };
  expectClose(at(ell("hfEllConeX"), 3, 2, 4), 9 - 1 - 1);
  expectClose(at(ell("hfEllConeY"), 2, 3, 4), 9 - 1 - 1);
  expectClose(at(ell("hfEllConeZ"), 1, 1, 1), 1 - 0.25 - 1.0 / 16);
}

TEST(HfLibPrimitives, Superellipsoid) {
  auto x = xyz();
  auto c = vals({0, 0, 0});
  // s1 = s2 = 1 is the unit sphere.
  Expr ball = call("hfSuperell", {arr(x), arr(c), sc(1.0), sc(1.0), sc(1.0), sc(1.0), sc(1.0)});
  expectClose(at(ball, 0.5, 0.5, 0.5), 0.25);
  Expr f = call("hfSuperell", {arr(x), arr(c), sc(2.0), sc(1.0), sc(3.0), sc(0.5), sc(2.0)});
  double X = 0.6 / 2, Y = 0.3, Z = 1.2 / 3;
  double expect = 1 - std::pow(std::pow(X, 1.0) + std::pow(Y, 1.0), 4.0) - std::pow(Z, 4.0);
  expectClose(at(f, -0.6, 0.3, -1.2), expect);
}

TEST(HfLibPrimitives, Blobby) {
  auto x = xyz();
  auto x0 = vals({0, 2}), y0 = vals({0, 0}), z0 = vals({0, 0}), a = vals({1, 2}),
       b = vals({1, 3});
  Expr f = call("hfBlobby", {arr(x), arr(x0), arr(y0), arr(z0), arr(a), arr(b), sc(0.5)});
  expectClose(at(f, 1, 0, 0), std::exp(-1.0) + 3 * std::exp(-2.0) - 0.5);
  expectClose(at(f, 0, 1, 0), std::exp(-1.0) + 3 * std::exp(-2.0 * 5) - 0.5);
}

TEST(HfLibPrimitives, BlobbyArraySizes) {
  auto x = xyz();
  auto x0 = vals({0, 1, 2}), y0 = vals({0, 1, 2}), z0 = vals({0, 1}), a = vals({1, 1, 1}),
       b = vals({1, 1, 1});
  auto err = errorOf("hfBlobby", {arr(x), arr(x0), arr(y0), arr(z0), arr(a), arr(b), sc(1.0)});
  EXPECT_EQ(err.first,
            "hfBlobby: arrays x0, y0, z0, a, b must have the same size (got 3, 3, 2, 3, 3)");
  EXPECT_EQ(err.second, 3);
  auto shortX = vals({0, 0});
  err = errorOf("hfBlobby", {arr(shortX, "xx"), arr(x0), arr(y0), arr(x0), arr(a), arr(b),
                             sc(1.0)});
  EXPECT_EQ(err.first, "hfBlobby: array xx must have at least 3 elements (got 2)");
  EXPECT_EQ(err.second, 0);
}

TEST(HfLibPrimitives, Metaball) {
  auto x = xyz();
  auto x0 = vals({0, 10, 20}), y0 = vals({0, 0, 0}), z0 = vals({0, 0, 0}), b = vals({2, 1, 5}),
       d = vals({3, 2, -1});
  Expr f = call("hfMetaball", {arr(x), arr(x0), arr(y0), arr(z0), arr(b), arr(d), sc(0.25)});
  // r = 0.5 <= d/3 = 1: b (1 - 3 r^2 / d^2); other balls too far.
  expectClose(at(f, 0.5, 0, 0), 2 * (1 - 3 * 0.25 / 9) - 0.25);
  // r = 2: d/3 < r < d: 1.5 b (1 - r/d)^2
  expectClose(at(f, 0, 2, 0), 1.5 * 2 * (1 - 2.0 / 3) * (1 - 2.0 / 3) - 0.25);
  // second ball at r = 1.5 < 2, first at r = 8.5 > 3; the d < 0 ball never counts
  expectClose(at(f, 11.5, 0, 0), 1.5 * 1 * (1 - 1.5 / 2) * (1 - 1.5 / 2) - 0.25);
  expectClose(at(f, 20, 0, 0), -0.25);
}

TEST(HfLibPrimitives, Soft) {
  auto x = xyz();
  auto x0 = vals({0, 3}), y0 = vals({0, 0}), z0 = vals({0, 0}), d = vals({2, 1});
  Expr f = call("hfSoft", {arr(x), arr(x0), arr(y0), arr(z0), arr(d), sc(0.1)});
  auto wy = [](double r, double dd) {
    double q = r * r / (dd * dd);
    return 1 - 22.0 / 9 * q + 17.0 / 9 * q * q - 4.0 / 9 * q * q * q;
  };
  expectClose(at(f, 1, 0, 0), wy(1, 2) - 0.1);
  expectClose(at(f, 2.5, 0, 0), wy(0.5, 1) - 0.1);  // first at r = 2.5 > 2 contributes 0
  expectClose(at(f, 0, 0, 0), 1 - 0.1);
  auto err = errorOf("hfSoft", {arr(x), arr(x0), arr(y0), arr(z0), arr(x), sc(0.1)});
  EXPECT_EQ(err.first, "hfSoft: arrays x0, y0, z0, d must have the same size (got 2, 2, 2, 3)");
}
