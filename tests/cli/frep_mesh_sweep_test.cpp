// frep mesh of an OBJ part swept along keyframes by translation (frSweepKeys, path_sweep.h): the
// exact sum with the path, no search, the same bytes for 0 and 2 workers, a watertight mesh with
// the volume of the swept boxes.
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli/farm_runner.h"
#include "core/mesh_checks.h"
#include "frep/geometry/distance_fields.h"
#include "frep/io/mesh_reader.h"

namespace frep_cli_test {
namespace {

// The unit cube [0, 1]^3 as an OBJ of 12 triangles.
std::string cubeObj() {
  const int c[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const int t[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                        {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::string s;
  for (const auto& p : c)
    s += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (const auto& k : t)
    s += "f " + std::to_string(k[0] + 1) + " " + std::to_string(k[1] + 1) + " " + std::to_string(k[2] + 1) + "\n";
  return s;
}

class MeshSweep : public FarmTest {};

// The cube moved (0.05, 0.05, 0.05) -> (2.05, 0.05, 0.05) -> (2.05, 1.55, 0.05) covers the union
// of [0.05, 3.05] x [0.05, 1.05] and [2.05, 3.05] x [0.05, 2.55] (z in [0.05, 1.05]): 3 + 1.5.
TEST_F(MeshSweep, OfAnObjPartAlongKeyframesIsExactWatertightAndTheSameForAnyWorkers) {
  std::system(("mkdir -p '" + path("parts") + "'").c_str());
  write("parts/cube.obj", cubeObj());
  write("sweep.hf",
        "part(x[3], a[1]) { part = frMesh(x, \"parts/cube.obj\"); }\n"
        "my_model(x[3], a[1]) {\n  array ts[3], ps[9];\n  ts = [0, 1, 3];\n"
        "  ps = [0.05, 0.05, 0.05,  2.05, 0.05, 0.05,  2.05, 1.55, 0.05];\n"
        "  my_model = frSweepKeys(x, part, ts, ps);\n}\n");
  const std::string box = " -b -0.3,-0.3,-0.3,3.4,2.9,1.4 --res 48 ";
  RunResult r0 = run("mesh sweep.hf" + box + "--workers 0 -O w0.ply");
  ASSERT_EQ(r0.code, 0) << r0.err;
  RunResult r2 = run("mesh sweep.hf" + box + "--workers 2 -O w2.ply");
  ASSERT_EQ(r2.code, 0) << r2.err;
  const std::string bytes = readText(path("w0.ply"));
  EXPECT_FALSE(bytes.empty());
  EXPECT_TRUE(bytes == readText(path("w2.ply")));
  const std::string report = readText(path("w2.ply.report.json"));
  EXPECT_NE(report.find("exact Minkowski sum sweep of parts/cube.obj (12 triangles) along a path of 3 points"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("\"searches\": 0"), std::string::npos) << report;
  const frep::Mesh m = frep::io::readMesh(path("w2.ply"));
  std::vector<mesh_checks::Vec3> positions;
  std::vector<mesh_checks::Tri> triangles;
  for (const auto& p : m.positions) positions.push_back({p[0], p[1], p[2]});
  for (const auto& t : m.triangles) triangles.push_back({t[0], t[1], t[2]});
  EXPECT_EQ(mesh_checks::checkEdgePairs(triangles, positions.size()), "");  // no unpaired edge
  EXPECT_NEAR(mesh_checks::enclosedVolume(positions, triangles) / 4.5, 1.0, 0.01);
}

}  // namespace
}  // namespace frep_cli_test
