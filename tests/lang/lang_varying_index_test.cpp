// Array reads at an index that depends on x (hfp rounds it per point, ties up): values against
// the direct computation, the clamping out of range, and sound interval bounds.
#include <cmath>
#include <random>

#include "frep/evaluators/interval.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const char* kStaircase =
    "stairs(x[3], a[1]) {\n"
    "  array h[4];\n"
    "  h = [0.5, 1.5, 2.5, 3.5];\n"
    "  u = x[1];\n"
    "  stairs = h[floor(u) + 1] - x[3];\n"
    "}\n";

double heights(int i) { return 0.5 + std::min(3, std::max(0, i)); }

TEST(LangVaryingIndex, StaircaseValues) {
  Model m = compileOk(kStaircase);
  for (double u : {0.0, 0.2, 0.99, 1.0, 1.7, 2.5, 3.2, 3.999}) {
    EXPECT_CLOSE(evalModel(m, {u, 0, 1}), heights(int(std::floor(u))) - 1);
  }
  // Out of range: clamped to the first and last element.
  EXPECT_CLOSE(evalModel(m, {-3.5, 0, 0}), 0.5);
  EXPECT_CLOSE(evalModel(m, {7.2, 0, 0}), 3.5);
}

TEST(LangVaryingIndex, RoundsToNearestTiesUp) {
  Model m = compileOk("m(x[3], a[1]) { array v[3]; v = [10, 20, 30]; m = v[x[1]]; }");
  EXPECT_CLOSE(evalModel(m, {1.49, 0, 0}), 10.0);
  EXPECT_CLOSE(evalModel(m, {1.5, 0, 0}), 20.0);   // tie goes up
  EXPECT_CLOSE(evalModel(m, {2.5, 0, 0}), 30.0);
  EXPECT_CLOSE(evalModel(m, {2.4999, 0, 0}), 20.0);
  // Elements may themselves depend on x.
  Model n = compileOk("m(x[3], a[1]) { array v[2]; v = [x[2], x[3] * 2]; m = v[x[1]]; }");
  EXPECT_CLOSE(evalModel(n, {1, 5, 7}), 5.0);
  EXPECT_CLOSE(evalModel(n, {2, 5, 7}), 14.0);
}

TEST(LangVaryingIndex, IntervalBoundsContainEveryValue) {
  Model m = compileOk(kStaircase);
  auto tape = Tape::compile(m.field, 3);
  IntervalEvaluator iv;
  PointEvaluator pt;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-2, 6), W(0, 2.5);
  for (int t = 0; t < 300; ++t) {
    Interval box[3];
    for (auto& b : box) {
      double lo = U(rng);
      b = Interval(lo, lo + W(rng));
    }
    Interval r = iv.eval(*tape, box);
    for (int s = 0; s < 20; ++s) {
      double p[3];
      for (int a = 0; a < 3; ++a)
        p[a] = box[a].lo + (box[a].hi - box[a].lo) * std::uniform_real_distribution<double>(0, 1)(rng);
      double v = pt.eval(*tape, p);
      ASSERT_LE(r.lo, v);
      ASSERT_GE(r.hi, v);
    }
  }
  // A box inside one step gets that step's value exactly (up to the x[3] term).
  Interval one[3] = {Interval(1.1, 1.9), Interval(0, 1), Interval(0, 0)};
  Interval r = iv.eval(*tape, one);
  EXPECT_DOUBLE_EQ(r.lo, 1.5);
  EXPECT_DOUBLE_EQ(r.hi, 1.5);
}

}  // namespace
}  // namespace frep::lang::testing
