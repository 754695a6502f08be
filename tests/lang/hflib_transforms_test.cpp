// hf* space transformations: they rewrite the array they are given and return 1.
#include "lang/hflib_test_util.h"

using namespace hftest;

namespace {
// Values of the three (possibly symbolic) coordinates at a point.
std::vector<double> coordsAt(const std::vector<Expr>& xt, double x, double y, double z) {
  return {at(xt[0], x, y, z), at(xt[1], x, y, z), at(xt[2], x, y, z)};
}
}  // namespace

TEST(HfLibTransforms, Shift3DMutatesItsArray) {
  auto xt = xyz();
  Expr r = call("hfShift3D", {arr(xt), sc(1.0), sc(2.0), sc(3.0)});
  EXPECT_TRUE(r.isConst(1.0));
  auto v = coordsAt(xt, 5, 5, 5);
  expectClose(v[0], 4);
  expectClose(v[1], 3);
  expectClose(v[2], 2);
  // A sphere on the shifted array is centred at (1, 2, 3).
  auto c = vals({0, 0, 0});
  Expr s = call("hfSphere", {arr(xt), arr(c), sc(1.0)});
  expectClose(at(s, 1, 2, 3), 1.0);
  expectClose(at(s, 2, 2, 3), 0.0);
}

TEST(HfLibTransforms, Scale3DAndStretch3D) {
  auto xt = xyz();
  call("hfScale3D", {arr(xt), sc(2.0), sc(4.0), sc(0.5)});
  auto v = coordsAt(xt, 1, 2, 3);
  expectClose(v[0], 0.5);
  expectClose(v[1], 0.5);
  expectClose(v[2], 6);
  auto yt = xyz();
  auto x0 = vals({1, 1, 1});
  call("hfStretch3D", {arr(yt), arr(x0), sc(2.0), sc(1.0), sc(4.0)});
  v = coordsAt(yt, 3, 5, -3);
  expectClose(v[0], 1 + 2.0 / 2);
  expectClose(v[1], 5);
  expectClose(v[2], 1 + (-4.0) / 4);
}

TEST(HfLibTransforms, Rotate3DZBy90MapsXToMinusY) {
  // hfp convention: x' = x cos + y sin, y' = -x sin + y cos, so (1,0,0) -> (0,-1,0): the object
  // turns counter-clockwise by theta (the array holds the inverse-mapped point).
  auto xt = vals({1, 0, 0});
  call("hfRotate3DZ", {arr(xt), sc(kPi / 2)});
  ASSERT_TRUE(xt[0].isConst() && xt[1].isConst() && xt[2].isConst());
  EXPECT_NEAR(xt[0].constValue(), 0.0, 1e-15);
  expectClose(xt[1].constValue(), -1.0);
  expectClose(xt[2].constValue(), 0.0);
  auto yt = xyz();
  call("hfRotate3DZ", {arr(yt), sc(0.3)});
  auto v = coordsAt(yt, 2, 3, 4);
  expectClose(v[0], 2 * std::cos(0.3) + 3 * std::sin(0.3));
  expectClose(v[1], -2 * std::sin(0.3) + 3 * std::cos(0.3));
  expectClose(v[2], 4);
}

TEST(HfLibTransforms, Rotate3DXAndY) {
  auto xt = xyz();
  call("hfRotate3DX", {arr(xt), sc(0.7)});
  auto v = coordsAt(xt, 2, 3, 4);  // (y, z) rotate
  expectClose(v[0], 2);
  expectClose(v[1], 3 * std::cos(0.7) + 4 * std::sin(0.7));
  expectClose(v[2], -3 * std::sin(0.7) + 4 * std::cos(0.7));
  auto yt = xyz();
  call("hfRotate3DY", {arr(yt), sc(0.7)});
  v = coordsAt(yt, 2, 3, 4);  // (z, x) rotate
  expectClose(v[2], 4 * std::cos(0.7) + 2 * std::sin(0.7));
  expectClose(v[0], -4 * std::sin(0.7) + 2 * std::cos(0.7));
  expectClose(v[1], 3);
}

TEST(HfLibTransforms, TwistZ) {
  auto xt = xyz();
  call("hfTwistZ", {arr(xt), sc(0.0), sc(2.0), sc(0.0), sc(kPi / 2)});
  // z = 1: t = 0.5, theta = pi/4
  auto v = coordsAt(xt, 1, 0, 1);
  expectClose(v[0], std::cos(kPi / 4));
  expectClose(v[1], -std::sin(kPi / 4));
  expectClose(v[2], 1);
  // z = 4: unclamped, t = 2, theta = pi
  v = coordsAt(xt, 1, 2, 4);
  expectClose(v[0], -1);
  expectClose(v[1], -2);
}

TEST(HfLibTransforms, TwistX) {
  auto xt = xyz();
  call("hfTwistX", {arr(xt), sc(-1.0), sc(1.0), sc(0.2), sc(0.6)});
  double th = 0.5 * 0.2 + 0.5 * 0.6;  // x = 0
  auto v = coordsAt(xt, 0, 1, 2);
  expectClose(v[1], 1 * std::cos(th) + 2 * std::sin(th));
  expectClose(v[2], -1 * std::sin(th) + 2 * std::cos(th));
}

TEST(HfLibTransforms, TaperZ) {
  auto xt = xyz();
  call("hfTaperZ", {arr(xt), sc(0.0), sc(2.0), sc(1.0), sc(3.0)});
  auto v = coordsAt(xt, 4, 6, 1);  // scale 2
  expectClose(v[0], 2);
  expectClose(v[1], 3);
  expectClose(v[2], 1);
  v = coordsAt(xt, 4, 6, -5);  // below u1: s1 = 1
  expectClose(v[0], 4);
  v = coordsAt(xt, 6, 6, 7);  // above u2: s2 = 3
  expectClose(v[0], 2);
  expectClose(v[1], 2);
}

TEST(HfLibTransforms, TaperXWithZeroScaleUsesOne) {
  auto xt = xyz();
  call("hfTaperX", {arr(xt), sc(0.0), sc(1.0), sc(0.0), sc(0.0)});
  auto v = coordsAt(xt, 0.5, 6, 7);
  expectClose(v[1], 6);
  expectClose(v[2], 7);
  auto yt = xyz();
  call("hfTaperY", {arr(yt), sc(0.0), sc(1.0), sc(2.0), sc(4.0)});
  v = coordsAt(yt, 6, 0.5, 9);  // scale 3, divides z and x
  expectClose(v[0], 2);
  expectClose(v[2], 3);
}

TEST(HfLibTransforms, SpaceMaps) {
  auto src = vals({0, 0, 0}), dst = vals({1, 0, 0}), b = vals({2, 2, 2});
  auto xt = xyz();
  call("hfSpaceMapCubic", {arr(xt), arr(src), arr(dst), arr(b)});
  // dt = (1,0,0); u = (0.5/(2*2), 0, 0) at (1.5, 0, 0): r = 0.125
  double r = 0.125, w = std::pow(1 - r, 3) / (1 + r);
  expectClose(at(xt[0], 1.5, 0, 0), 1.5 - w);
  expectClose(at(xt[0], 9, 0, 0), 9);  // r = 2 > 1: no effect
  auto yt = xyz();
  call("hfSpaceMapExp", {arr(yt), arr(src), arr(dst), arr(b)});
  double r2 = 0.125 * 0.125 + 0.5 * 0.5;  // at (1.5, 1, 0): u = (0.125, 0.5, 0)
  expectClose(at(yt[0], 1.5, 1, 0), 1.5 - std::exp(-r2));
  expectClose(at(yt[1], 1.5, 1, 0), 1.0);
}

TEST(HfLibTransforms, SpaceMapArraySizes) {
  auto src = vals({0, 0, 0}), dst = vals({1, 0, 0, 1}), b = vals({2, 2, 2});
  auto xt = xyz();
  auto err = errorOf("hfSpaceMapCubic", {arr(xt), arr(src, "s"), arr(dst, "d"), arr(b, "b")});
  EXPECT_EQ(err.first,
            "hfSpaceMapCubic: arrays s, d, b must have the same size, a multiple of 3 (got 3, 4, 3)");
  auto two = vals({1, 2});
  err = errorOf("hfShift3D", {arr(two, "p"), sc(1.0), sc(2.0), sc(3.0)});
  EXPECT_EQ(err.first, "hfShift3D: array p must have at least 3 elements (got 2)");
}
