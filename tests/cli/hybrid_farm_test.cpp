// Models that read meshes, through the farm: the same grid for 0 and 2 workers and from another
// working directory, a cluster worker that has no copy of the file (it travels in the job's
// model_files), and mesh -> signed distance -> frep mesh back within half a voxel (Hausdorff,
// both directions). The worker's refusal of a file whose hash differs: tests/farm/farm_test.cpp.
// Composition through the farm: an OBJ part + a ball (the exact offset path, Steiner's volume)
// and a swept mesh tool cut out of a .vdb block that frep sample wrote (closure), each the same
// for 0 and 2 workers.
#include <unistd.h>

#include <cmath>

#include "cli/farm_runner.h"
#include "frep/geometry/distance_fields.h"
#include "frep/io/mesh_reader.h"
#include "frep/io/vdb_reader.h"
#include "frep/sampling/sample.h"

namespace frep_cli_test {
namespace {

const double kC[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
const int kT[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                       {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};

std::string cubeObj() {
  std::string s;
  for (auto& p : kC) s += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (auto& t : kT) s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return s;
}

class HybridFarm : public FarmTest {
 protected:
  void SetUp() override {
    FarmTest::SetUp();
    std::system(("mkdir -p '" + path("parts") + "' '" + path("elsewhere") + "'").c_str());
    write("parts/cube.obj", cubeObj());
    write("m.hf", "m(x[3], a[1]) {\n  m = frMesh(x, \"parts/cube.obj\");\n}\n");
  }
};

TEST_F(HybridFarm, SampleIsTheSameForAnyWorkerCountAndWorkingDirectory) {
  const std::string box = " -b -0.3,-0.3,-0.3,1.3,1.3,1.3 --res 48 ";
  RunResult r0 = run("sample m.hf" + box + "--workers 0 -O w0.vdb");
  ASSERT_EQ(r0.code, 0) << r0.err;
  RunResult r2 = run("sample m.hf" + box + "--workers 2 -O w2.vdb");
  ASSERT_EQ(r2.code, 0) << r2.err;
  RunResult r3 = capture("cd elsewhere && '" FREP_BINARY "' sample ../m.hf" + box + "--workers 3 -O ../w3.vdb");
  ASSERT_EQ(r3.code, 0) << r3.err;
  // The files differ in their frep_command metadata; the grid's checksum covers the voxels.
  auto checksum = [&](const std::string& name) {
    const std::string b = readText(path(name));
    const size_t at = b.find("frep_grid_checksum");
    return at == std::string::npos ? std::string() : b.substr(at, 48);
  };
  const std::string a = checksum("w0.vdb");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, checksum("w2.vdb"));
  EXPECT_FALSE(checksum("w3.vdb").empty());  // from another working directory: found and sampled
}

TEST_F(HybridFarm, AClusterWorkerWithoutTheFileGetsItInTheJob) {
  const std::string box = " -b -0.3,-0.3,-0.3,1.3,1.3,1.3 --res 48 ";
  RunResult r0 = run("sample m.hf" + box + "--workers 0 -O in.vdb");
  ASSERT_EQ(r0.code, 0) << r0.err;
  const int port = 20000 + int(::getpid() % 20000);
  const std::string ep = "tcp://127.0.0.1:" + std::to_string(port);
  pid_t master = start("sample m.hf" + box + "--listen " + ep + " --expect-workers 1 --heartbeat-ms 100 --no-progress -O cl.vdb");
  // The worker runs in an empty directory: parts/cube.obj is nowhere it could look.
  const std::string worker = std::string(FREP_BINARY).substr(0, std::string(FREP_BINARY).rfind('/')) + "/frep-worker";
  RunResult w = capture("cd elsewhere && '" + worker + "' --connect " + ep + " --threads 2 --master-timeout 20");
  EXPECT_EQ(waitFor(master), 0) << readText(path(".bg.err"));
  EXPECT_EQ(w.code, 0) << w.err;
  auto checksum = [&](const std::string& name) {
    const std::string b = readText(path(name));
    const size_t at = b.find("frep_grid_checksum");
    return at == std::string::npos ? std::string() : b.substr(at, 48);
  };
  EXPECT_FALSE(checksum("in.vdb").empty());
  EXPECT_EQ(checksum("in.vdb"), checksum("cl.vdb"));
}

TEST_F(HybridFarm, MeshRoundTripIsWithinHalfAVoxel) {
  RunResult r = run("mesh m.hf -b -0.3,-0.3,-0.3,1.3,1.3,1.3 --res 64 --workers 2 -O back.obj");
  ASSERT_EQ(r.code, 0) << r.err;
  const frep::Mesh backMesh = frep::io::readMesh(path("back.obj"));
  struct {
    std::vector<double> xyz;
    std::vector<uint32_t> tris;
  } back;
  for (const auto& p : backMesh.positions) back.xyz.insert(back.xyz.end(), p.begin(), p.end());
  for (const auto& t : backMesh.triangles) back.tris.insert(back.tris.end(), t.begin(), t.end());
  const double voxel = 1.6 / 63;  // --res: points along the longest axis
  // Mesh vertices -> cube surface.
  std::vector<double> cxyz;
  for (auto& p : kC) cxyz.insert(cxyz.end(), p, p + 3);
  std::vector<uint32_t> ct;
  for (auto& t : kT) ct.insert(ct.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
  frep::MeshField cube(cxyz, ct, "cube");
  double worst = 0;
  for (size_t i = 0; i < back.xyz.size(); i += 3) worst = std::max(worst, cube.distance(&back.xyz[i]));
  EXPECT_LT(worst, 0.5 * voxel);
  // Cube surface -> mesh (points on every face, edges and corners included).
  frep::MeshField mesh(back.xyz, back.tris, "back");
  double worst2 = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {0.0, 1.0})
      for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j) {
          double p[3];
          p[axis] = side;
          p[(axis + 1) % 3] = i / 20.0;
          p[(axis + 2) % 3] = j / 20.0;
          worst2 = std::max(worst2, mesh.distance(p));
        }
  EXPECT_LT(worst2, 0.5 * voxel);
}

TEST_F(HybridFarm, MeshPartPlusBallIsTheSameThroughTheFarmWithSteinersVolume) {
  write("sum.hf",
        "part(x[3], a[1]) { part = frMesh(x, \"parts/cube.obj\"); }\n"
        "ball(x[3], a[1]) { array c[3]; c = [0.1, 0, -0.05]; ball = frBall(x, 0.25, c); }\n"
        "my_model(x[3], a[1]) { my_model = frMinkowski(x, part, ball); }\n");
  const std::string box = " -b -0.3,-0.4,-0.45,1.5,1.4,1.35 --res 40 ";
  RunResult r0 = run("mesh sum.hf" + box + "--workers 0 -O in.ply");
  ASSERT_EQ(r0.code, 0) << r0.err;
  RunResult r2 = run("mesh sum.hf" + box + "--workers 2 -O w2.ply");
  ASSERT_EQ(r2.code, 0) << r2.err;
  const std::string bytes = readText(path("in.ply"));
  EXPECT_FALSE(bytes.empty());
  EXPECT_TRUE(bytes == readText(path("w2.ply")));  // the same bytes
  // The exact path ran (no search) and the report says so.
  const std::string report = readText(path("w2.ply.report.json"));
  EXPECT_NE(report.find("exact Minkowski sum parts/cube.obj (12 triangles) as a box + ball(r 0.25 at (0.1, 0, -0.05))"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("\"searches\": 0"), std::string::npos) << report;
  // Cube (a = 1) + ball: V = a^3 + 6 a^2 r + 3 pi a r^2 + 4/3 pi r^3 (Steiner), and the
  // triangle mesh's volume within 1%.
  const frep::Mesh m = frep::io::readMesh(path("w2.ply"));
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  for (const auto& p : m.positions) xyz.insert(xyz.end(), p.begin(), p.end());
  for (const auto& t : m.triangles) tris.insert(tris.end(), t.begin(), t.end());
  const double r = 0.25, steiner = 1 + 6 * r + 3 * M_PI * r * r + 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(frep::MeshField(xyz, tris, "out").volume() / steiner, 1.0, 0.01);
}

// The block [-0.45, 3.45] x [-0.45, 1.45] x [-0.45, 0.45] is sampled to a .vdb first and read
// back as the stock; the tool (the unit cube mesh) swept by (2t + 0.05, 0.05, 0.05), t in
// [0, 1], removes [0.05, 3.05] x [0.05, 1.05] x [0.05, 0.45] from it. Every face lies half a
// voxel (0.05) from the lattice of voxel 0.1.
class HybridSweptCut : public HybridFarm {
 protected:
  void sampleBoth() {
    write("block.hf",
          "block(x[3], a[1]) { block = min(min(min(x[1] + 0.45, 3.45 - x[1]), min(x[2] + 0.45, 1.45 - x[2])),"
          " min(x[3] + 0.45, 0.45 - x[3])); }\n");
    write("cut.hf",
          "tool(x[3], a[1]) { tool = frMesh(x, \"parts/cube.obj\"); }\n"
          "px(x[1], a[1]) { px = 2 * x[1] + 0.05; }\n"
          "pq(x[1], a[1]) { pq = 0.05; }\n"
          "stock(x[3], a[1]) { stock = frVolume(x, \"block.vdb\"); }\n"
          "my_model(x[3], a[1]) {\n  swept = frSweep(x, tool, px, pq, pq, 0, 1);\n  my_model = stock(x, a) & -swept;\n}\n");
    const std::string box = " -b -1,-1,-1,4,2,1 --res 51 ";
    ASSERT_EQ(run("sample block.hf" + box + "--workers 0 -O block.vdb").code, 0);
    RunResult r0 = run("sample cut.hf" + box + "--workers 0 -O in.vdb");
    ASSERT_EQ(r0.code, 0) << r0.err;
    RunResult r2 = run("sample cut.hf" + box + "--workers 2 -O w2.vdb");
    ASSERT_EQ(r2.code, 0) << r2.err;
  }
};

TEST_F(HybridSweptCut, ASweptMeshToolCutFromAScannedBlockIsTheSameThroughTheFarm) {
  sampleBoth();
  auto checksum = [&](const std::string& name) {
    const std::string b = readText(path(name));
    const size_t at = b.find("frep_grid_checksum");
    return at == std::string::npos ? std::string() : b.substr(at, 48);
  };
  EXPECT_FALSE(checksum("in.vdb").empty());
  EXPECT_EQ(checksum("in.vdb"), checksum("w2.vdb"));
  // Material was removed: fewer inside points than the block alone.
  const frep::SampleResult s = frep::io::readSampledVdb(path("w2.vdb"), "").samples;
  EXPECT_LT(frep::insideVolume(s), 3.9 * 1.9 * 0.9 - 0.5);
}

// The signed-distance store keeps every sampled sign: OpenVDB's rebuild alone flipped 8 voxels
// next to the slot's ends at z = 0.4 (e.g. (0.1, 0, 0.4): -0.022 where f = +0.029).
TEST_F(HybridSweptCut, ASweptMeshToolCutFromAScannedBlockIsTheExactSolid) {
  sampleBoth();
  // The inside lattice points are those of the exact solid (no point is within half a voxel
  // of its boundary): volume 3.9 * 1.9 * 0.9 - 3 * 1 * 0.4 on the lattice.
  const frep::SampleResult s = frep::io::readSampledVdb(path("w2.vdb"), "").samples;
  const double expected = frep::latticeVolume(s.grid, [](const std::array<double, 3>& p) {
    const bool block = p[0] > -0.45 && p[0] < 3.45 && p[1] > -0.45 && p[1] < 1.45 && p[2] > -0.45 && p[2] < 0.45;
    const bool swept = p[0] > 0.05 && p[0] < 3.05 && p[1] > 0.05 && p[1] < 1.05 && p[2] > 0.05 && p[2] < 1.05;
    return block && !swept;
  });
  EXPECT_NEAR(expected, 3.9 * 1.9 * 0.9 - 3 * 1 * 0.4, 1e-9);
  EXPECT_NEAR(frep::insideVolume(s), expected, 1e-9);
}

TEST_F(HybridFarm, ThePaperExamplesCompile) {
  for (const char* m : {"bezier9", "polygon12", "naca0011", "aircraft"}) {
    RunResult r = run(std::string("check '" FREP_EXAMPLES_DIR "/hybrid/") + m + ".hf'");
    EXPECT_EQ(r.code, 0) << m << ": " << r.err;
  }
}

TEST_F(HybridFarm, MissingFileIsAModelErrorAtTheCall) {
  write("bad.hf", "m(x[3], a[1]) {\n  m = frMesh(x, \"parts/none.stl\");\n}\n");
  RunResult r = run("check bad.hf");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("bad.hf:2:17: error: cannot open file 'parts/none.stl'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace frep_cli_test
