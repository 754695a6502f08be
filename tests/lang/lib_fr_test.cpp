// frepfarm's fr* library functions, called through the registry with constant arguments.
#include <gtest/gtest.h>

#include <cmath>

#include "hflib_test_util.h"

using namespace hftest;
using frep::Op;

namespace {

// Value of a call whose arguments are all constants (it folds to one number).
double value(const std::string& name, std::vector<Arg> args) {
  Expr e = call(name, std::move(args));
  EXPECT_TRUE(e.isConst()) << name << ": " << frep::toString(e);
  return e.isConst() ? e.constValue() : NAN;
}

}  // namespace

TEST(FrLibrary, SetOperationsWithParameter) {
  EXPECT_EQ(value("frUnion", {sc(3.0), sc(4.0), sc(0.0)}), 12.0);
  EXPECT_EQ(value("frIntersection", {sc(3.0), sc(4.0), sc(0.0)}), 2.0);
  EXPECT_EQ(value("frSubtraction", {sc(3.0), sc(4.0), sc(0.0)}), -6.0);
  EXPECT_EQ(value("frUnion", {sc(3.0), sc(4.0), sc(1.0)}), 4.0);
  EXPECT_EQ(value("frIntersection", {sc(3.0), sc(4.0), sc(1.0)}), 3.0);
  EXPECT_DOUBLE_EQ(value("FRUNION", {sc(3.0), sc(4.0), sc(0.5)}), (7 + std::sqrt(13.0)) / 1.5);
  // a = 1 on fields: an exact max node, so interval pruning can decide it.
  EXPECT_EQ(call("frUnion", {sc(Expr::x(0)), sc(Expr::x(1)), sc(1.0)}).op(), Op::Max);
  auto err = errorOf("frUnion", {sc(3.0), sc(4.0), sc(2.0)});
  EXPECT_NE(err.first.find("frUnion"), std::string::npos) << err.first;
  EXPECT_EQ(err.second, 2);
}

TEST(FrLibrary, SmoothAndBlendedSetOperations) {
  EXPECT_EQ(value("frUnionSmooth", {sc(3.0), sc(4.0), sc(1.0)}), 60.0);
  EXPECT_EQ(value("frIntersectionSmooth", {sc(3.0), sc(4.0), sc(2.0)}), 50.0);
  EXPECT_EQ(errorOf("frUnionSmooth", {sc(3.0), sc(4.0), sc(Expr::x(0))}).second, 2);
  EXPECT_DOUBLE_EQ(value("frBlendUnion", {sc(3.0), sc(4.0), sc(1.0), sc(1.0), sc(2.0)}),
                   12.0 + 1.0 / 14.0);
  EXPECT_DOUBLE_EQ(value("frBlendIntersection", {sc(3.0), sc(4.0), sc(1.0), sc(1.0), sc(2.0)}),
                   2.0 + 1.0 / 14.0);
  EXPECT_EQ(value("frBlendUnion", {sc(0.0), sc(0.0), sc(0.5), sc(1.0), sc(1.0)}), 0.5);
}

TEST(FrLibrary, OffsetAndMorph) {
  EXPECT_EQ(value("frOffset", {sc(3.0), sc(0.5)}), 3.5);
  EXPECT_EQ(value("frMorph", {sc(3.0), sc(5.0), sc(0.25)}), 3.5);
  EXPECT_EQ(value("frMorph", {sc(3.0), sc(5.0), sc(0.0)}), 3.0);
  EXPECT_EQ(value("frMorph", {sc(3.0), sc(5.0), sc(1.0)}), 5.0);
}

TEST(FrLibrary, TwistRewritesTheCoordinateArray) {
  std::vector<Expr> xt = xyz();
  EXPECT_EQ(value("frTwist", {arr(xt, "xt"), sc(3.0), sc(0.0), sc(1.0), sc(0.0), sc(kPi / 2)}),
            1.0);
  // A cylinder of radius 0.5 around the line x = 2, y = 0, read through the twisted xt: at
  // z = 1 it has turned a quarter, so its axis passes through (0, 2, 1).
  Expr cyl = 0.25 - frep::square(xt[0] - 2.0) - frep::square(xt[1]);
  EXPECT_NEAR(at(cyl, 0, 2, 1), 0.25, 1e-14);
  EXPECT_NEAR(at(cyl, 2, 0, 0), 0.25, 1e-14);
}

TEST(FrLibrary, TaperAndBend) {
  std::vector<Expr> xt = xyz();
  EXPECT_EQ(value("frTaper", {arr(xt), sc(3.0), sc(0.0), sc(1.0), sc(1.0), sc(2.0)}), 1.0);
  Expr unitCyl = 1.0 - frep::square(xt[0]) - frep::square(xt[1]);
  EXPECT_EQ(at(unitCyl, 1.5, 0, 0.5), 0.0);
  EXPECT_EQ(at(unitCyl, 0, 2, 3), 0.0);
  std::vector<Expr> xb = xyz();
  EXPECT_EQ(value("frBend", {arr(xb), sc(1.0), sc(2.0), sc(2.0)}), 1.0);
  Expr bar = 0.01 - frep::square(xb[1]);  // |y| <= 0.1 along x, bent around (0, 2)
  EXPECT_NEAR(at(bar, 2, 2, 0), 0.01, 1e-14);
  EXPECT_EQ(at(bar, 0, 2, 0), 0.01 - 4.0);
}

TEST(FrLibrary, TransformErrorsNameTheArgument) {
  std::vector<Expr> xt = xyz();
  EXPECT_EQ(errorOf("frTwist", {arr(xt), sc(4.0), sc(0.0), sc(1.0), sc(0.0), sc(1.0)}).second, 1);
  EXPECT_EQ(
      errorOf("frTwist", {arr(xt), sc(Expr::x(0)), sc(0.0), sc(1.0), sc(0.0), sc(1.0)}).second, 1);
  EXPECT_EQ(errorOf("frBend", {arr(xt), sc(1.0), sc(1.0), sc(2.0)}).second, 2);
  EXPECT_EQ(errorOf("frBend", {arr(xt), sc(1.0), sc(2.0), sc(0.0)}).second, 3);
  auto taper = errorOf("frTaper", {arr(xt), sc(3.0), sc(0.0), sc(1.0), sc(1.0), sc(-1.0)});
  EXPECT_NE(taper.first.find("same sign"), std::string::npos) << taper.first;
  std::vector<Expr> shortXt = {Expr::x(0)};
  EXPECT_EQ(errorOf("frTaper", {arr(shortXt), sc(3.0), sc(0.0), sc(1.0), sc(1.0), sc(2.0)}).second,
            0);
}

TEST(FrLibrary, OffsetAlongTheNormalMovesTheSurfaceByD) {
  // Unit sphere f = 1 - |x|^2 offset by D = 0.5 along its normal: the surface is at radius 1.5.
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr f = call("frOffsetNormal", {sc(1.0 - x * x - y * y - z * z), sc(0.5)});
  auto tape = frep::Tape::compile(f, 3);
  frep::PointEvaluator pe;
  double on[3] = {1.5, 0, 0}, in[3] = {0, 1.4, 0}, out[3] = {0, 0, -1.6};
  EXPECT_NEAR(pe.eval(*tape, on), 0.0, 1e-12);
  EXPECT_GT(pe.eval(*tape, in), 0.0);
  EXPECT_LT(pe.eval(*tape, out), 0.0);
}
