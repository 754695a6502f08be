// Perturbation freeforms (Vyatkin-Perturbation eq. 10) against the formula, point by point, and
// their interval bounds against sampled values.
#include <cmath>
#include <random>

#include "frep/evaluators/interval.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

double cubePos(double q) { return q >= 0 ? q * q * q : 0.0; }

TEST(LibFrPerturbation, PerturbAddsTheCubedNonNegativePart) {
  std::vector<double> p = {0.3, -0.4, 0.2};
  // Base: unit sphere; quadric Q = 0.25 - (x - 0.5)^2 - y^2 - z^2.
  Model m = compileOk(
      "m(x[3], a[1]) { f = 1 - x[1]^2 - x[2]^2 - x[3]^2;"
      " m = frPerturb(f, 0.25 - (x[1] - 0.5)^2 - x[2]^2 - x[3]^2); }");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  for (int i = 0; i < 200; ++i) {
    double x = U(rng), y = U(rng), z = U(rng);
    double F = 1 - x * x - y * y - z * z, Q = 0.25 - (x - 0.5) * (x - 0.5) - y * y - z * z;
    EXPECT_CLOSE(evalModel(m, {x, y, z}), F + cubePos(Q));
  }
}

const char* kFreeform =
    "m(x[3], a[1]) {\n"
    "  array c[6], r[6], h[2];\n"
    "  c = [0, 0, 1, 0.6, 0, 0];\n"
    "  r = [0.5, 0.5, 0.4, 0.3, 0.6, 0.3];\n"
    "  h = [0.8, -0.5];\n"
    "  m = frPerturbQuadric(x, 1 - x[1]^2 - x[2]^2 - x[3]^2, c, r, h);\n"
    "}\n";

double freeform(double x, double y, double z) {
  const double c[6] = {0, 0, 1, 0.6, 0, 0}, r[6] = {0.5, 0.5, 0.4, 0.3, 0.6, 0.3}, h[2] = {0.8, -0.5};
  const double p[3] = {x, y, z};
  double f = 1 - x * x - y * y - z * z;
  for (int i = 0; i < 2; ++i) {
    double q = 1;
    for (int k = 0; k < 3; ++k) q -= std::pow((p[k] - c[3 * i + k]) / r[3 * i + k], 2);
    f += h[i] * cubePos(q);
  }
  return f;
}

TEST(LibFrPerturbation, QuadricBumpsMatchTheFormula) {
  Model m = compileOk(kFreeform);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  for (int i = 0; i < 300; ++i) {
    double x = U(rng), y = U(rng), z = U(rng);
    EXPECT_CLOSE(evalModel(m, {x, y, z}), freeform(x, y, z));
  }
  // The bump's height at its centre, and nothing outside its ellipsoid.
  EXPECT_CLOSE(evalModel(m, {0, 0, 1}), 0.8);
  EXPECT_CLOSE(evalModel(m, {0, 0, -1}), 0.0);
}

TEST(LibFrPerturbation, IntervalBoundsContainSampledValues) {
  Model m = compileOk(kFreeform);
  auto tape = Tape::compile(m.field, 3);
  IntervalEvaluator iv;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1.5, 1.5), W(0, 0.8), T(0, 1);
  for (int t = 0; t < 200; ++t) {
    Interval box[3];
    for (auto& b : box) {
      double lo = U(rng);
      b = Interval(lo, lo + W(rng));
    }
    Interval r = iv.eval(*tape, box);
    for (int s = 0; s < 20; ++s) {
      double v = freeform(box[0].lo + (box[0].hi - box[0].lo) * T(rng), box[1].lo + (box[1].hi - box[1].lo) * T(rng),
                          box[2].lo + (box[2].hi - box[2].lo) * T(rng));
      ASSERT_LE(r.lo, v + 1e-12);
      ASSERT_GE(r.hi, v - 1e-12);
    }
  }
}

TEST(LibFrPerturbation, ZeroSemiAxisIsAnError) {
  CompileResult r = compile(
      "m(x[3], a[1]) { array c[3], r[3], h[1]; c = [0,0,0]; r = [1,0,1]; h = [1];"
      " m = frPerturbQuadric(x, 1, c, r, h); }",
      "t.hf");
  ASSERT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("frPerturbQuadric: semi-axis 2 of r is zero"), std::string::npos)
      << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
