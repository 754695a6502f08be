// Prospero (Fidget's 7,866-op challenge, ../shared/corpus/fidget/prospero.hf) sliced at 1024^2 in
// float with the certified double fallback (PlaneOptions::floatSigns): every pixel's sign class
// is that of the double values, with one, two and TBB's default threads (the same bytes each
// time), and most pixels are certified in float.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "frep/evaluators/float_error.h"
#include "frep/lang/hyperfun.h"
#include "frep/sampling/plane.h"
#include "shared_corpus.h"

namespace {

namespace fs = std::filesystem;
using namespace frep;

int signClass(double f) { return std::isnan(f) ? 2 : f >= 0 ? 1 : 0; }

TEST(ProsperoFloatSlice, SignImageIsTheDoublePathsAt1024) {
  const fs::path dir = fs::path(FREP_SHARED_DIR) / "corpus" / "fidget";
  FREP_NEED_CORPUS(dir);
  std::ifstream in(dir / "prospero.hf");
  ASSERT_TRUE(in) << "cannot read prospero.hf";
  std::stringstream text;
  text << in.rdbuf();
  lang::CompileResult r = lang::compile(text.str(), "prospero.hf");
  ASSERT_TRUE(r.ok);
  TapePtr tape = Tape::compile(bindParams(r.model.field, {Expr(0.0)}), 3);
  ASSERT_TRUE(FloatErrorBound::supports(*tape));
  PlaneLattice l;
  l.normal = 2;
  l.origin[0] = l.origin[1] = -1.0;
  l.step = 2.0 / 1023.0;
  l.width = l.height = 1024;
  const std::vector<double> values = evaluatePlane(tape, l);  // double, every evaluated pixel exact
  std::vector<double> first;  // the one-thread image, which every thread count must give byte for byte
  for (int threads : {1, 2, 0}) {
    PlaneOptions o;
    o.signOnly = o.floatSigns = true;
    o.threads = threads;
    PlaneStats st;
    const std::vector<double> f = evaluatePlane(tape, l, o, &st);
    size_t wrong = 0;
    for (size_t i = 0; i < values.size(); ++i) wrong += signClass(values[i]) != signClass(f[i]);
    EXPECT_EQ(wrong, 0u) << threads << " thread(s)";
    EXPECT_GT(st.floatPixels, 100 * st.doublePixels);  // the fallback stays rare
    EXPECT_EQ(st.floatPixels + st.doublePixels + st.decidedPixels, values.size());
    if (first.empty()) first = f;
    else EXPECT_EQ(std::memcmp(first.data(), f.data(), f.size() * sizeof(double)), 0) << threads << " thread(s)";
  }
}

}  // namespace
