// hfNoiseG, hfSawtooth, hfBezierVolume, the hfA_* attribute functions, the complete hf* name
// list, and library calls from .hf source (array mutation seen by later statements).
#include "lang/hflib_test_util.h"
#include "lang/lang_test_util.h"

using namespace hftest;

TEST(HfLibMisc, NoiseG) {
  auto x = xyz();
  double amp = 0.7, fr = 1.3, ph = 0.4, p[3] = {0.3, -1.1, 2.0};
  Expr f = call("hfNoiseG", {arr(x), sc(amp), sc(fr), sc(ph)});
  auto S = [&](int i) {
    double prev = std::sin(fr * p[(i + 2) % 3]);
    return amp * std::sin(fr * p[i]) + amp / 1.17 * std::sin(fr * p[i] / 1.35 + ph * prev);
  };
  expectClose(at(f, p[0], p[1], p[2]), S(0) * S(1) * S(2));
  expectClose(at(f, 0, 0, 0), 0.0);
}

TEST(HfLibMisc, Sawtooth) {
  double t = 0.3, a = 2.0, fr = 1.5;
  Expr f = call("hfSawtooth", {sc(Expr::x(0)), sc(3.0), sc(a), sc(fr)});
  double sum = std::sin(2 * kPi * fr * t) + std::sin(4 * kPi * fr * t) / 2;
  expectClose(at(f, t), 2 / (a * kPi) * (0.5 - sum));
  expectClose(at(f, 0), 2 / (a * kPi) * 0.5);
  EXPECT_TRUE(call("hfSawtooth", {sc(Expr::x(0)), sc(1.0), sc(a), sc(fr)}).isConst(0.0));
  auto err = errorOf("hfSawtooth", {sc(0.1), sc(Expr::x(0)), sc(a), sc(fr)});
  EXPECT_EQ(err.first, "hfSawtooth: the number of terms n must be a constant known at compile time");
  EXPECT_EQ(err.second, 1);
}

TEST(HfLibMisc, BezierVolume) {
  auto x = xyz();
  auto box = vals({0, 0, 0, 2, 1, 1});
  auto w = vals({1, 2, 3, 4, 5, 6, 7, 8});  // l = m = n = 2, index (i*2 + j)*2 + k
  Expr f = call("hfBezierVolume", {arr(x), sc(2.0), sc(2.0), sc(2.0), arr(box), arr(w)});
  double px = 0.5, py = 0.5, pz = 0.75;
  double u = px / 2, v = py, s = pz;  // j pairs with z (s), k with y (v)
  double B[2][2] = {{1 - u, u}, {1 - s, s}}, C[2] = {1 - v, v}, sum = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) sum += B[0][i] * B[1][j] * C[k] * (i * 4 + j * 2 + k + 1);
  auto rint = [](double a, double b) { return a + b - std::sqrt(a * a + b * b); };
  double bx = (2 - px) * px, by = (1 - py) * py, bz = (1 - pz) * pz;
  expectClose(at(f, px, py, pz), rint(rint(rint(bx, by), bz), sum));
  auto shortW = vals({1, 2, 3});
  auto err = errorOf("hfBezierVolume", {arr(x), sc(2.0), sc(2.0), sc(2.0), arr(box), arr(shortW, "w")});
  EXPECT_EQ(err.first, "hfBezierVolume: array w must have 8 elements (l*m*n control values) (got 3)");
  EXPECT_EQ(err.second, 5);
}

TEST(HfLibMisc, AttributeFunctionsReturnOne) {
  auto x = xyz();
  const auto* f = frep::lang::findLibraryFunction("hfA_SetColor");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->signature, "*");
  std::vector<Arg> args = {sc(Expr::x(0)), arr(x), sc(1.0), sc(0.0), sc(0.0)};
  EXPECT_TRUE(f->lower(args).isConst(1.0));
  EXPECT_TRUE(x[0].same(Expr::x(0)));  // no effect on arrays
}

TEST(HfLibMisc, EveryHfNameIsRegistered) {
  const char* names[] = {
      "hfSphere", "hfEllipsoid", "hfCylinderX", "hfCylinderY", "hfCylinderZ", "hfEllCylX",
      "hfEllCylY", "hfEllCylZ", "hfTorusX", "hfTorusY", "hfTorusZ", "hfBlock", "hfConeX",
      "hfConeY", "hfConeZ", "hfEllConeX", "hfEllConeY", "hfEllConeZ", "hfSuperell", "hfBlobby",
      "hfMetaball", "hfSoft", "hfNoiseG", "hfConvPoint", "hfConvLine", "hfConvCurve",
      "hfConvTriangle", "hfConvMesh", "hfConvArc", "hfBezierVolume", "hfScale3D", "hfShift3D",
      "hfRotate3DX", "hfRotate3DY", "hfRotate3DZ", "hfTwistX", "hfTwistY", "hfTwistZ",
      "hfTaperX", "hfTaperY", "hfTaperZ", "hfStretch3D", "hfSpaceMapCubic", "hfSpaceMapExp",
      "hfBlendUni", "hfBlendInt", "hfDConeX", "hfDConeY", "hfDConeZ", "hfDCylinder",
      "hfDEllipsoid", "hfDTorusX", "hfDTorusY", "hfDTorusZ", "hfDBlendUni", "hfDBlendInt",
      "hfSawtooth", "hfA_SetColor", "hfA_Turbulence"};
  for (const char* n : names) {
    const auto* f = frep::lang::findLibraryFunction(n);
    ASSERT_NE(f, nullptr) << n;
    EXPECT_FALSE(f->summary.empty()) << n;
    for (char c : f->signature) EXPECT_TRUE(c == 'A' || c == 'S' || c == '*') << n;
  }
}

TEST(HfLibMisc, CallsFromSourceMutateArrays) {
  using namespace frep::lang::testing;
  frep::lang::Model m = compileOk(
      "my_model(x[3], a[1]) {\n"
      "  array c[3], xt[3];\n"
      "  c = [0, 0, 0];\n"
      "  xt[1] = x[1]; xt[2] = x[2]; xt[3] = x[3];\n"
      "  d = hfShift3D(xt, 1, 2, 3);\n"
      "  d = hfRotate3DZ(xt, 1.5707963267948966);\n"
      "  my_model = hfSphere(xt, c, 2) + d - 1;\n"
      "}\n");
  // xt = rotZ(x - (1,2,3)): at (2,2,3): (1,0,0) -> (0,-1,0), |.|^2 = 1
  EXPECT_CLOSE(evalModel(m, {2, 2, 3}), 4.0 - 1.0);
  EXPECT_CLOSE(evalModel(m, {1, 2, 3}), 4.0);
  EXPECT_CLOSE(evalModel(m, {1, 4, 5}), 4.0 - 8.0);
}
