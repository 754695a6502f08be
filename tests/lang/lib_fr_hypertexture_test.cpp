// Hypertexture over a boundary layer (lang/src/library/fr_hypertexture.cpp): outside the layer
// the field is the base field bit for bit, inside it moves by at most the amplitude, the surface
// stays in the layer, and interval bounds contain sampled values.
#include <cmath>
#include <random>

#include "frep/evaluators/interval.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

// Unit ball, a layer 0.3 thick in F (F = 1 - r^2: |F| < 0.3 is 0.837 < r < 1.14), amplitude 0.2.
const char* kTextured =
    "m(x[3], a[1]) {\n"
    "  f = 1 - x[1]^2 - x[2]^2 - x[3]^2;\n"
    "  m = frHypertexture(x, f, 0.2, 4, 0.3, 17, 3);\n"
    "}\n";

double ballF(double x, double y, double z) { return 1 - x * x - y * y - z * z; }

// The model's field at many points through one tape.
struct Sampler {
  explicit Sampler(const Model& m) : tape(Tape::compile(m.field, 3)) {}
  double operator()(double x, double y, double z) {
    double p[3] = {x, y, z};
    return ev.eval(*tape, p);
  }
  TapePtr tape;
  PointEvaluator ev;
};

TEST(LibFrHypertexture, OutsideTheLayerTheFieldIsUnchangedExactly) {
  Sampler m(compileOk(kTextured));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1.6, 1.6);
  int outside = 0, inside = 0;
  double largest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double x = U(rng), y = U(rng), z = U(rng), f = ballF(x, y, z);
    const double v = m(x, y, z);
    if (std::fabs(f) >= 0.3 * (1 + 1e-12)) {
      ASSERT_EQ(v, f) << x << " " << y << " " << z;
      ++outside;
    } else {
      ASSERT_LE(std::fabs(v - f), 0.2 + 1e-12);
      largest = std::max(largest, std::fabs(v - f));
      ++inside;
    }
  }
  EXPECT_GT(outside, 1000);
  EXPECT_GT(inside, 1000);
  EXPECT_GT(largest, 0.05);  // the texture does something in the layer
}

TEST(LibFrHypertexture, TheSurfaceStaysInTheLayer) {
  // Along rays from the centre the textured field changes sign only where |F| < min(T, A).
  Sampler m(compileOk(kTextured));
  std::mt19937 rng(2);
  std::normal_distribution<double> N(0, 1);
  for (int r = 0; r < 200; ++r) {
    double d[3] = {N(rng), N(rng), N(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double prev = m(0, 0, 0), prevT = 0.0;
    for (int k = 1; k <= 600; ++k) {
      const double t = 1.5 * k / 600;
      const double v = m(t * d[0] / len, t * d[1] / len, t * d[2] / len);
      if ((v >= 0) != (prev >= 0)) {
        // 1 - r^2 = +-0.2 at r = sqrt(0.8), sqrt(1.2): the crossing lies between them.
        EXPECT_GE(t, std::sqrt(0.8) - 1e-9);
        EXPECT_LE(prevT, std::sqrt(1.2) + 1e-9);
      }
      prev = v, prevT = t;
    }
  }
}

TEST(LibFrHypertexture, IntervalBoundsContainSampledValues) {
  Model m = compileOk(kTextured);
  auto tape = Tape::compile(m.field, 3);
  IntervalEvaluator iv;
  PointEvaluator pe;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.4, 1.4), T(0, 1);
  for (double w : {0.002, 0.05, 0.5}) {
    for (int b = 0; b < 300; ++b) {
      Interval box[3];
      for (auto& i : box) {
        const double lo = U(rng);
        i = Interval(lo, lo + w * T(rng));
      }
      const Interval r = iv.eval(*tape, box);
      for (int s = 0; s < 20; ++s) {
        double p[3] = {box[0].lo + box[0].width() * T(rng), box[1].lo + box[1].width() * T(rng),
                       box[2].lo + box[2].width() * T(rng)};
        const double v = pe.eval(*tape, p);
        ASSERT_GE(v, r.lo);
        ASSERT_LE(v, r.hi);
      }
    }
  }
}

TEST(LibFrHypertexture, NoiseIsAPrimitiveInMinusOneToOne) {
  Model m = compileOk("m(x[3], a[1]) { m = frNoise(x, 2, 5); }");
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> U(-3, 3);
  double lo = 1, hi = -1;
  for (int i = 0; i < 5000; ++i) {
    const double v = evalModel(m, {U(rng), U(rng), U(rng)});
    lo = std::min(lo, v), hi = std::max(hi, v);
  }
  EXPECT_GE(lo, -1.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_LT(lo, -0.2);
  EXPECT_GT(hi, 0.2);
}

TEST(LibFrHypertexture, BadArgumentsNameTheArgument) {
  auto diag = [](const std::string& call) {
    return allDiagnostics(compile("m(x[3], a[1]) { f = 1 - x[1]^2; m = " + call + "; }", "t.hf"));
  };
  EXPECT_NE(diag("frHypertexture(x, f, 0.1, 2, 0, 1)").find("layer thickness must be a finite number > 0"),
            std::string::npos);
  EXPECT_NE(diag("frHypertexture(x, f, 0.1, 2, 0.2, 1.5)").find("seed must be an integer"), std::string::npos);
  EXPECT_NE(diag("frHypertexture(x, f, 0.1, 2, 0.2, 1, 20)").find("octaves must be an integer 1 to 16"),
            std::string::npos);
  EXPECT_NE(diag("frHypertexture(x, f, 0.1, x[1], 0.2, 1)").find("frequency must be a constant"), std::string::npos);
  EXPECT_NE(diag("frNoise(x, -1, 1)").find("frequency must be a finite number > 0"), std::string::npos);
}

}  // namespace
}  // namespace frep::lang::testing
