// frConv<Kernel><Skeleton> (lang/src/library/fr_convolution.cpp): the language calls reach the core
// convolution (frep/primitives/convolution.h, tested against numerical integration in
// tests/core/convolution_test.cpp) with the right arguments, the arc's rotation and degrees, and
// the diagnostics. Exact values where the integral is elementary.
#include <cmath>

#include "frep/lang/library/library.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(FrConvolution, TheFamilyIsRegistered) {
  const char* kernels[] = {"Gauss", "Inverse", "InverseSquare", "Metaball", "Soft", "Quartic"};
  const char* skeletons[] = {"Point", "Segment", "Arc", "Triangle", "Plane"};
  int n = 0;
  for (const char* k : kernels)
    for (const char* s : skeletons) {
      bool plane = std::string(s) == "Plane", inverse = std::string(k).rfind("Inverse", 0) == 0;
      const LibraryFunction* f = findLibraryFunction(std::string("frConv") + k + s);
      EXPECT_EQ(f != nullptr, !(plane && inverse)) << k << s;
      n += f != nullptr;
    }
  EXPECT_EQ(n, 28);
}

TEST(FrConvolution, PointKernelsAreEq1To6) {
  // One point at the origin, S = 2, at distance 0.3 (q = 0.6), threshold 0.1.
  const std::string pre = "array c[3], sw[1]; c = [0, 0, 0]; sw = [2]; my_model = frConv";
  auto v = [&](const char* k) {
    Model m = compileOk(std::string("my_model(x[3], a[1]) { ") + pre + k + "Point(x, c, sw, 0.1); }");
    return evalModel(m, {0.3, 0, 0});
  };
  double q = 0.6;
  EXPECT_CLOSE(v("Gauss"), std::exp(-q * q) - 0.1);
  EXPECT_CLOSE(v("Inverse"), 1 / q - 0.1);
  EXPECT_CLOSE(v("InverseSquare"), 1 / (q * q) - 0.1);
  EXPECT_CLOSE(v("Metaball"), 1.5 * (1 - q) * (1 - q) - 0.1);
  EXPECT_CLOSE(v("Soft"), 1 - 4.0 / 9 * std::pow(q, 6) + 17.0 / 9 * std::pow(q, 4) - 22.0 / 9 * q * q - 0.1);
  EXPECT_CLOSE(v("Quartic"), (1 - q * q) * (1 - q * q) - 0.1);
}

TEST(FrConvolution, SegmentAndPlaneClosedForms) {
  // Gauss over the segment (0,0,0)-(1,0,0), S = 1, at (0.5, 0.4, 0): sqrt(pi) e^-0.16 erf(0.5).
  Model seg = compileOk(
      "my_model(x[3], a[1]) { array b[3], e[3], sw[1]; b = [0, 0, 0]; e = [1, 0, 0]; sw = [1];"
      " my_model = frConvGaussSegment(x, b, e, sw, 0); }");
  EXPECT_CLOSE(evalModel(seg, {0.5, 0.4, 0}), std::sqrt(kPi) * std::exp(-0.16) * std::erf(0.5));
  // Quartic over the plane z = 0 (normal (0,0,3)), S = 0.5, at height 1: pi (1 - 0.25)^3 / (3 * 0.25).
  Model pl = compileOk(
      "my_model(x[3], a[1]) { array p[3], n[3], sw[1]; p = [0, 0, 0]; n = [0, 0, 3]; sw = [0.5];"
      " my_model = frConvQuarticPlane(x, p, n, sw, 0); }");
  EXPECT_CLOSE(evalModel(pl, {7, -3, 1}), kPi * std::pow(0.75, 3) / 0.75);
}

TEST(FrConvolution, ArcRotationAndDegrees) {
  // A full circle of radius 1 about c = (1, 2, 3) turned 90 degrees about x: it lies in the
  // xz-plane, so (1, 2 + h, 3) is on its axis at distance sqrt(1 + h^2) from every point.
  Model m = compileOk(
      "my_model(x[3], a[1]) { array c[3], r[1], th[1], ax[3], an[1], sw[1];"
      " c = [1, 2, 3]; r = [1]; th = [360]; ax = [1, 0, 0]; an = [90]; sw = [0.5];"
      " my_model = frConvGaussArc(x, c, r, th, ax, an, sw, 0); }");
  double h = 0.7, d2 = 1 + h * h;
  EXPECT_NEAR(evalModel(m, {1, 2 + h, 3}), 2 * kPi * std::exp(-0.25 * d2), 1e-10);
  // Half the circle (180 degrees) sees half of it from the axis.
  Model half = compileOk(
      "my_model(x[3], a[1]) { array c[3], r[1], th[1], ax[3], an[1], sw[1];"
      " c = [1, 2, 3]; r = [1]; th = [180]; ax = [1, 0, 0]; an = [90]; sw = [0.5];"
      " my_model = frConvGaussArc(x, c, r, th, ax, an, sw, 0); }");
  EXPECT_NEAR(evalModel(half, {1, 2 + h, 3}), kPi * std::exp(-0.25 * d2), 1e-10);
}

TEST(FrConvolution, TriangleMatchesTheSumOfItsHalves) {
  // The unit square as two triangles equals ... the same square split along the other diagonal.
  auto at = [](const char* v) {
    Model m = compileOk(std::string("my_model(x[3], a[1]) { array v[18], sw[2]; v = [") + v +
                        "]; sw = [1.3, 1.3]; my_model = frConvSoftTriangle(x, v, sw, 0); }");
    return evalModel(m, {0.3, 0.8, 0.25});
  };
  EXPECT_NEAR(at("0,0,0, 1,0,0, 1,1,0,  0,0,0, 1,1,0, 0,1,0"), at("0,0,0, 1,0,0, 0,1,0,  1,0,0, 1,1,0, 0,1,0"), 1e-12);
}

TEST(FrConvolution, Diagnostics) {
  auto err = [](const std::string& body) {
    CompileResult r = compile("my_model(x[3], a[1]) { " + body + " }", "test.hf");
    EXPECT_FALSE(r.ok);
    return allDiagnostics(r);
  };
  EXPECT_NE(err("array c[3], sw[1]; c = [a[1], 0, 0]; sw = [1]; my_model = frConvGaussPoint(x, c, sw, 0);")
                .find("must be known at compile time"),
            std::string::npos);
  EXPECT_NE(err("array b[3], e[3], sw[1]; b = [0, 0, 0]; e = [0, 0, 0]; sw = [1];"
                " my_model = frConvQuarticSegment(x, b, e, sw, 0);")
                .find("zero length"),
            std::string::npos);
  EXPECT_NE(err("array c[6], sw[1]; c = [0, 0, 0, 1, 1, 1]; sw = [1]; my_model = frConvGaussPoint(x, c, sw, 0);")
                .find("must have 3 elements"),
            std::string::npos);
  EXPECT_NE(err("array p[3], n[3], sw[1]; p = [0, 0, 0]; n = [0, 0, 1]; sw = [1];"
                " my_model = frConvInversePlane(x, p, n, sw, 0);"),
            "");
}

// Relations as constants: nested balls, disjoint balls, and a 0.02 overlap a coarse grid misses.
const std::string kBalls =
    "big(x[3], a[1]) { big = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
    "small(x[3], a[1]) { small = 0.09 - (x[1] - 0.2)^2 - x[2]^2 - x[3]^2; }\n"
    "far(x[3], a[1]) { far = 0.25 - (x[1] - 3)^2 - x[2]^2 - x[3]^2; }\n"
    // Touches big's surface from outside with a 0.02 overlap: centre at 1.48, radius 0.5.
    "thin(x[3], a[1]) { thin = 0.25 - (x[1] - 1.48)^2 - x[2]^2 - x[3]^2; }\n"
    "apart(x[3], a[1]) { apart = 0.25 - (x[1] - 1.52)^2 - x[2]^2 - x[3]^2; }\n";

double relation(const std::string& call) {
  Model m = compileOk(kBalls + "my_model(x[3], a[1]) { array o[6]; o = [-2, 0.9, -2, 2, -2, 2]; my_model = " +
                      call + "; }");
  return evalModel(m, {0, 0, 0});
}

TEST(FrRelations, NestedDisjointAndThinOverlap) {
  EXPECT_EQ(relation("frIntersects(big, small)"), 1);
  EXPECT_EQ(relation("frInside(small, big)"), 1);
  EXPECT_EQ(relation("frInside(big, small)"), 0);
  EXPECT_EQ(relation("frIntersects(big, far)"), 0);
  EXPECT_EQ(relation("frInside(far, big)"), 0);
  EXPECT_EQ(relation("frIntersects(big, thin)"), 1);
  EXPECT_EQ(relation("frIntersects(big, apart)"), 0);
  // The 96^3 cell centres over [-2, 2]^3 (spacing 0.042) miss the 0.02-thick lens.
  int both = 0;
  for (int i = 0; i < 96; ++i)
    for (int j = 0; j < 96; ++j)
      for (int k = 0; k < 96; ++k) {
        double x = -2 + 4 * (i + 0.5) / 96, y = -2 + 4 * (j + 0.5) / 96, z = -2 + 4 * (k + 0.5) / 96;
        both += 1 - x * x - y * y - z * z >= 0 && 0.25 - (x - 1.48) * (x - 1.48) - y * y - z * z >= 0;
      }
  EXPECT_EQ(both, 0);
  // An explicit box that excludes the overlap: disjoint there.
  EXPECT_EQ(relation("frIntersects(big, thin, o)"), 0);
  // Touching balls: a common point (1, 0, 0) exists, so never "disjoint" (1 if a box centre
  // lands on it, else undecided).
  Model touch = compileOk(
      "u(x[3], a[1]) { u = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
      "v(x[3], a[1]) { v = 1 - (x[1] - 2)^2 - x[2]^2 - x[3]^2; }\n"
      "my_model(x[3], a[1]) { my_model = frIntersects(u, v); }");
  EXPECT_NE(evalModel(touch, {0, 0, 0}), 0);
}

TEST(FrRelations, Diagnostics) {
  CompileResult r = compile(kBalls + "my_model(x[3], a[1]) { my_model = frIntersects(big, 2); }", "test.hf");
  EXPECT_FALSE(r.ok);
  r = compile(kBalls + "my_model(x[3], a[1]) { array o[3]; o = [0, 1, 2]; my_model = frInside(big, small, o); }",
              "test.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("options array needs 6 or 7"), std::string::npos) << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
