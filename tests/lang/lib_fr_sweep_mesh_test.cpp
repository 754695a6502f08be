// frSweepKeys of an frMesh part by translation (path_sweep.h, mesh_convex_sum.h with the path's
// segments): no extremum search, the exact distance to the swept box outside; with angles the
// sweep still searches.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "frep/evaluators/eval.h"
#include "frep/geometry/distance_fields.h"
#include "frep/lang/library/library.h"
#include "frep/minkowski_algebra/registry.h"
#include "lang/lang_test_util.h"

using namespace frep;
using namespace frep::lang;
using namespace frep::lang::testing;

namespace {

// The unit cube [0, 1]^3 as 12 triangles, whatever the bytes.
LoadedFileField cubeLoader(const FileFieldRequest&) {
  const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const uint32_t t[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::vector<double> xyz;
  for (const auto& p : c) xyz.insert(xyz.end(), p, p + 3);
  std::vector<uint32_t> tris;
  for (const auto& k : t) tris.insert(tris.end(), k, k + 3);
  LoadedFileField l;
  l.field = std::make_shared<MeshField>(xyz, tris, "parts/cube.obj");
  l.fileHash = 7;
  return l;
}

// The exact distance from p to the box [lo, hi] (0 inside).
double boxDistance(const std::vector<double>& p, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  double s = 0;
  for (size_t a = 0; a < 3; ++a) {
    const double d = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    s += d * d;
  }
  return std::sqrt(s);
}

}  // namespace

// The cube moved (0, 0, 0) -> (2, 0, 0) -> (2, 1.5, 0): the union of the boxes [0, 3] x [0, 1] x
// [0, 1] and [2, 3] x [0, 2.5] x [0, 1], its exact distance outside, no search.
TEST(FrSweepMesh, SweepKeysOfAMeshPartIsItsSumWithThePath) {
  FileFieldLoader saved = fileFieldLoader();
  setFileFieldLoader(cubeLoader);
  CompileOptions opt;
  opt.files["parts/cube.obj"] = "cube";
  const std::string part = "part(x[3], a[1]) { part = frMesh(x, \"parts/cube.obj\"); }\n";
  Model m = compileOk(part +
                          "my_model(x[3], a[1]) { array ts[3], ps[9]; ts = [0, 1, 3]; "
                          "ps = [0, 0, 0,  2, 0, 0,  2, 1.5, 0]; my_model = frSweepKeys(x, part, ts, ps); }",
                      opt);
  EXPECT_FALSE(Tape::compile(m.field, 3)->hasExtrema());
  const auto described = minkowski::describeExact(m.field);
  ASSERT_EQ(described.size(), 1u);
  EXPECT_NE(described[0].find("exact Minkowski sum sweep of parts/cube.obj (12 triangles) along a path of 3 points "
                              "(2 segments)"),
            std::string::npos)
      << described[0];
  for (const auto& p : std::vector<std::vector<double>>{
           {1, 0.5, 1.2}, {-0.3, 0.5, 0.5}, {1.5, 1.3, 0.5}, {3.4, 2.9, -0.2}, {1.2, 2, 0.5}, {2.5, 2.6, 1.1}}) {
    const double d = std::min(boxDistance(p, {0, 0, 0}, {3, 1, 1}), boxDistance(p, {2, 0, 0}, {3, 2.5, 1}));
    EXPECT_NEAR(evalModel(m, p), -d, 1e-12) << p[0] << "," << p[1] << "," << p[2];
  }
  EXPECT_GT(evalModel(m, {2.5, 2, 0.3}), 0);  // inside (0 on a diagonal of a face's prisms)
  EXPECT_GT(evalModel(m, {0.5, 0.3, 0.6}), 0);
  // With angles the sweep searches as before.
  Model turned =
      compileOk(part +
                    "my_model(x[3], a[1]) { array ts[2], ps[6], an[6]; ts = [0, 1]; ps = [0, 0, 0, 1, 0, 0]; "
                    "an = [0, 0, 0, 0, 0, 1]; my_model = frSweepKeys(x, part, ts, ps, an); }",
                opt);
  EXPECT_TRUE(Tape::compile(turned.field, 3)->hasExtrema());
  setFileFieldLoader(saved);
}
