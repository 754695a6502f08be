// An object whose dimension changes along a parameter (lang/src/library/fr_product.cpp): a disc
// times a segment of length t along x[3], t = x[4]. At t = 0 it is the flat disc (2D), for
// t > 0 a cylinder of volume 0.64 pi t (certified measure), for t < 0 empty.
#include <cmath>
#include <random>

#include "frep/measure/mass_properties.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const char* kGrowing =
    "disc(x[2], a[1]) { disc = 0.64 - x[1]^2 - x[2]^2; }\n"
    "my_model(x[4], a[1]) { my_model = frProduct(x, disc, 3, -0.5 * x[4], 0.5 * x[4]); }\n";

TEST(LibFrProduct, AtZeroLengthItIsTheFlatDisc) {
  Model m = compileOk(kGrowing);
  auto tape = Tape::compile(m.field, 4);
  PointEvaluator ev;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int i = 0; i < 5000; ++i) {
    const double x = U(rng), y = U(rng), z = U(rng), disc = 0.64 - x * x - y * y;
    double onPlane[4] = {x, y, 0, 0}, off[4] = {x, y, z, 0};
    EXPECT_EQ(ev.eval(*tape, onPlane), std::min(disc, 0.0));  // >= 0 exactly on the disc
    if (z != 0) EXPECT_LT(ev.eval(*tape, off), 0.0);
    double before[4] = {x, y, 0, -0.01};  // negative length: empty
    EXPECT_LT(ev.eval(*tape, before), 0.0);
  }
}

TEST(LibFrProduct, VolumeIsTheDiscTimesTheLength) {
  Model m = compileOk(kGrowing);
  const Interval box[3] = {{-1, 1}, {-1, 1}, {-1, 1}};
  MeasureOptions opt;
  opt.areaTolerance = false;  // the volume is the closed form checked
  for (double t : {0.25, 0.5, 1.0}) {
    Expr section = remap(m.field, {Expr::x(0), Expr::x(1), Expr::x(2), Expr(t)});
    MassProperties p = measureMassProperties(section, box, opt);
    const double exact = 0.64 * M_PI * t;
    EXPECT_LE(p.volume.lower, exact) << t;
    EXPECT_GE(p.volume.upper, exact) << t;
    EXPECT_LE(p.volume.width(), 0.005 * exact) << t;
    // Centroid on the axis, at the segment's middle.
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(p.centroid[size_t(k)].lower, 0.0);
      EXPECT_GE(p.centroid[size_t(k)].upper, 0.0);
    }
  }
}

TEST(LibFrProduct, BadAxisIsAnError) {
  CompileResult r = compile(std::string(kGrowing).replace(std::string(kGrowing).find(", 3,"), 4, ", 5,"), "t.hf");
  ASSERT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("frProduct: the axis must be an integer 1 to 4"), std::string::npos)
      << allDiagnostics(r);
}

}  // namespace
}  // namespace frep::lang::testing
