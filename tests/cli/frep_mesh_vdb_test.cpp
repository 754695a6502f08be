// frep mesh input.vdb: a FloatGrid written by frep sample meshed from its stored values (core
// meshSamples): watertight, oriented, volume, agreement with meshing the model directly, the
// grid's transform respected, and the errors (missing file, not a VDB, no such grid, a grid of
// another type, truncated file, options that do not apply) with their exit codes and no output.
#include <openvdb/openvdb.h>

#include <cmath>
#include <fstream>

#include "core/mesh_checks.h"
#include "frep_runner.h"
#include "mesh_files.h"

using namespace frep_cli_test;
namespace mc = mesh_checks;

namespace {

constexpr double kPi = 3.14159265358979323846;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

openvdb::FloatGrid::Ptr readFloatGrid(const std::string& path) {
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  openvdb::GridPtrVecPtr grids = file.getGrids();
  file.close();
  return openvdb::gridPtrCast<openvdb::FloatGrid>(grids->front());
}

// As another tool edits a frep file: the seal of frep sample's bytes no longer applies, so it is
// dropped (docs/cli.md); the other frep_ metadata stay.
void writeGrids(const std::string& path, const openvdb::GridPtrVec& grids) {
  for (const auto& g : grids) g->removeMeta("frep_grid_checksum");
  openvdb::io::File file(path);
  file.write(grids);
  file.close();
}

// Checks shared by every mesh of the unit sphere: closed, oriented, genus 0, outward normals.
void expectClosedSphere(const ReadMesh& m, double volume, double volumeTolerance) {
  ASSERT_GT(m.triangles.size(), 1000u);
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), 2);
  EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), volume, volumeTolerance * volume);
}

}  // namespace

TEST_F(FrepTest, MeshFromVdbIsWatertightAndAgreesWithTheModelMesh) {
  write("s.hf", kSphere);  // radius 1
  ASSERT_EQ(run("sample s.hf -b 1.5 -g 48 --store raw -O s.vdb").code, 0);
  RunResult r = run("mesh s.vdb -O v.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  ReadMesh v = readPly(readText(path("v.ply")));
  EXPECT_TRUE(contains(r.out, "wrote v.ply (binary PLY): " + std::to_string(v.positions.size()) + " vertices, " +
                                  std::to_string(v.triangles.size()) + " triangles"))
      << r.out;
  EXPECT_TRUE(contains(r.out, "from grid 'my_model' of s.vdb")) << r.out;
  EXPECT_TRUE(contains(r.out, "left out 0")) << r.out;
  // -g 48: voxel 1/16, so that +-1.5 are on sample's world lattice and mesh samples the same points.
  const double volume = 4.0 / 3.0 * kPi, voxel = 1.0 / 16;
  expectClosedSphere(v, volume, 0.01);
  EXPECT_NEAR(mc::surfaceArea(v.positions, v.triangles), 4 * kPi, 0.01 * 4 * kPi);
  EXPECT_EQ(mc::selfIntersections(v.positions, v.triangles), 0u);
  for (size_t i = 0; i < v.positions.size(); ++i) {
    const mc::Vec3& p = v.positions[i];
    ASSERT_GT(mc::dot(v.normals[i], p) / mc::norm(p), 0.95) << "vertex " << i;  // outward
    ASSERT_NEAR(mc::norm(p), 1.0, 0.25 * voxel) << "vertex " << i;           // world coordinates
  }

  // The model meshed directly: the same cells are crossed (the same signs), so the same edges
  // carry vertices, in the same (edge key) order, and each pair lies within a voxel (along an
  // edge that grazes the sphere the linear interpolant's root slides along the edge, ~0.6 voxel,
  // while staying on the surface to within 0.25 voxel, asserted above).
  ASSERT_EQ(run("mesh s.hf -b 1.5 -g 48 --tolerance 0 -O m.ply").code, 0);  // unsimplified, like the .vdb's
  ReadMesh m = readPly(readText(path("m.ply")));
  // The farm report gives the master's peak memory (ru_maxrss), here a few MB at least.
  for (const char* report : {"m.ply.report.json", "s.vdb.report.json"}) {
    const std::string json = readText(path(report));
    const size_t at = json.find("\"peak_rss_bytes\": ");
    ASSERT_NE(at, std::string::npos) << report;
    EXPECT_GT(std::stoull(json.substr(at + 18)), 1000000ull) << report;
  }
  ASSERT_EQ(m.positions.size(), v.positions.size());
  EXPECT_EQ(m.triangles.size(), v.triangles.size());
  double worst = 0, sum = 0;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const double d = mc::norm(mc::sub(m.positions[i], v.positions[i]));
    worst = std::max(worst, d);
    sum += d;
  }
  EXPECT_LT(worst, voxel);
  EXPECT_LT(sum / double(m.positions.size()), 0.05 * voxel);
  EXPECT_NEAR(mc::enclosedVolume(v.positions, v.triangles), mc::enclosedVolume(m.positions, m.triangles), 0.005 * volume);

  // Threads never change the bytes; OBJ and STL work as for models.
  ASSERT_EQ(run("mesh s.vdb --threads 1 -O v1.ply").code, 0);
  EXPECT_TRUE(readText(path("v1.ply")) == readText(path("v.ply")));
  ASSERT_EQ(run("mesh s.vdb -O v.stl").code, 0);
  EXPECT_EQ(readStl(readText(path("v.stl"))).triangles.size(), v.triangles.size());
  // A sample with the narrowest band (1 voxel) still has every crossed cell's corners active:
  // the same vertices and triangles (normals differ where a central difference reaches past the
  // band and uses an inactive voxel's +-band value).
  ASSERT_EQ(run("sample s.hf -b 1.5 -g 48 --band 1 --store raw -O b1.vdb").code, 0);
  RunResult b = run("mesh b1.vdb -O b1.ply");
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_TRUE(contains(b.out, "left out 0")) << b.out;
  ReadMesh b1 = readPly(readText(path("b1.ply")));
  EXPECT_TRUE(b1.positions == v.positions);
  EXPECT_TRUE(b1.triangles == v.triangles);
  // (0.85: on this lattice the worst such vertex turns its normal by 27 degrees, 0.893.)
  for (size_t i = 0; i < b1.normals.size(); ++i) ASSERT_GT(mc::dot(b1.normals[i], v.normals[i]), 0.85) << i;
}

TEST_F(FrepTest, MeshFromVdbFollowsTheGridTransform) {
  write("s.hf", kSphere);
  ASSERT_EQ(run("sample s.hf -b 1.5 --res 40 -O s.vdb").code, 0);
  ASSERT_EQ(run("mesh s.vdb -O ref.ply").code, 0);
  ReadMesh ref = readPly(readText(path("ref.ply")));
  const double volume = mc::enclosedVolume(ref.positions, ref.triangles);
  openvdb::FloatGrid::Ptr grid = readFloatGrid(path("s.vdb"));
  const openvdb::Vec3d origin = grid->indexToWorld(openvdb::Vec3d(0, 0, 0));
  const double voxel = grid->voxelSize()[0];

  // Uniform scale x2 and a translation: positions map exactly, volume x8.
  {
    auto xf = openvdb::math::Transform::createLinearTransform(2 * voxel);
    xf->postTranslate(openvdb::Vec3d(5, -3, 1));
    openvdb::FloatGrid::Ptr g = grid->deepCopy();
    g->setTransform(xf);
    writeGrids(path("scaled.vdb"), {g});
    ASSERT_EQ(run("mesh scaled.vdb -O scaled.ply").code, 0);
    ReadMesh m = readPly(readText(path("scaled.ply")));
    ASSERT_EQ(m.positions.size(), ref.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i)
      for (int a = 0; a < 3; ++a) {
        const double expect = (ref.positions[i][a] - origin[a]) * 2 + (a == 0 ? 5 : a == 1 ? -3 : 1);
        ASSERT_NEAR(m.positions[i][a], expect, 1e-5) << i;
      }
    EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), 8 * volume, 1e-4 * volume);
  }
  // Non-uniform scale with a mirror (x -> -x): still closed and outward, volume x |det|.
  {
    openvdb::Mat4d mat = openvdb::Mat4d::identity();
    mat.setToScale(openvdb::Vec3d(-voxel, 2 * voxel, 3 * voxel));
    openvdb::FloatGrid::Ptr g = grid->deepCopy();
    g->setTransform(openvdb::math::Transform::createLinearTransform(mat));
    writeGrids(path("mirror.vdb"), {g});
    RunResult r = run("mesh mirror.vdb -O mirror.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    ReadMesh m = readPly(readText(path("mirror.ply")));
    EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
    EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), 6 * volume, 1e-4 * 6 * volume);
    // Normals outward: towards increasing distance from the ellipsoid's centre, in its metric.
    const openvdb::Vec3d c = g->indexToWorld(grid->worldToIndex(openvdb::Vec3d(0, 0, 0)));
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const mc::Vec3 d{(m.positions[i][0] - c[0]) / 1.0, (m.positions[i][1] - c[1]) / 4.0, (m.positions[i][2] - c[2]) / 9.0};
      ASSERT_GT(mc::dot(m.normals[i], d), 0.0) << i;
    }
  }
}

TEST_F(FrepTest, MeshFromVdbRejectsBadInputs) {
  write("s.hf", kSphere);
  ASSERT_EQ(run("sample s.hf -b 1.5 --res 24 -O s.vdb").code, 0);
  write("text.vdb", "this is not a VDB file\n");
  {
    // A file with a vector grid only, and one with a float grid named "density" and a vector grid.
    openvdb::initialize();
    openvdb::Vec3SGrid::Ptr vec = openvdb::Vec3SGrid::create();
    vec->setName("velocity");
    vec->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
    writeGrids(path("vec.vdb"), {vec});
    openvdb::FloatGrid::Ptr sdf = readFloatGrid(path("s.vdb"));
    sdf->setName("density");
    writeGrids(path("two.vdb"), {vec, sdf});
  }
  {
    std::string bytes = readText(path("s.vdb"));
    std::ofstream(path("cut.vdb"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  struct Case {
    const char* args;
    int code;
    const char* message;
  } cases[] = {
      {"mesh none.vdb -O a.ply", 3, "cannot read VDB 'none.vdb'"},
      {"mesh text.vdb -O a.ply", 3, "cannot read VDB 'text.vdb'"},
      {"mesh cut.vdb -O a.ply", 3, "cannot read VDB 'cut.vdb'"},
      {"mesh vec.vdb -O a.ply", 1, "vec.vdb: no float grid to mesh (it holds 'velocity' (vec3s))"},
      {"mesh two.vdb -o velocity -O a.ply", 1, "grid 'velocity' holds vec3s values; frep mesh needs a float grid"},
      {"mesh two.vdb -o nosuch -O a.ply", 1, "two.vdb: no grid named 'nosuch' (-o/--object); it holds '"},
      {"mesh s.vdb -b 2 -O a.ply", 2, "-b/--bounds: 's.vdb' is a .vdb"},
      {"mesh s.vdb --res 32 -O a.ply", 2, "--res/-g: 's.vdb' is a .vdb"},
      {"mesh s.vdb -a 1 -O a.ply", 2, "-a/--params"},
      {"mesh s.vdb --tolerance 0.2 -O a.ply", 2, "--tolerance/--no-sharp: simplification checks every change"},
      {"mesh s.vdb --no-sharp -O a.ply", 2, "--tolerance/--no-sharp: simplification checks every change"},
      {"mesh s.vdb --resume -O a.ply", 2, "a .vdb is meshed in-process"},
      {"mesh s.vdb -O a.vdb", 2, "-O/--out: 'a.vdb' has no mesh extension"},
      {"mesh s.vdb -O nodir/a.ply", 3, "-O/--out"},
  };
  for (const Case& c : cases) {
    RunResult r = run(c.args);
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
  }
  // No output and no temporary file for any of them; the named float grid of a mixed file works.
  EXPECT_EQ(listing(), "cut.vdb s.hf s.vdb s.vdb.report.json text.vdb two.vdb vec.vdb");
  RunResult r = run("mesh two.vdb -O d.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "from grid 'density' of two.vdb")) << r.out;
  ASSERT_EQ(run("mesh two.vdb -o density -O e.ply").code, 0);
  EXPECT_TRUE(readText(path("d.ply")) == readText(path("e.ply")));
}

TEST_F(FrepTest, MeshBytesDoNotDependOnHowTheCommandIsSpelt) {
  // As frep sample's (SampleBytesDoNotDependOnHowTheCommandIsSpelt): another spelling of the
  // input's path, options in another order, -g for the same grid, another argv[0]; the files'
  // comments name the model by its hash (.hf) or the .vdb by its content hash.
  write("s.hf", kSphere);
  ASSERT_EQ(run("sample s.hf -b 1.5 --res 33 -O s.vdb").code, 0);
  ASSERT_EQ(std::system(("mkdir -p '" + path("sub") + "' && ln -s '" FREP_BINARY "' '" + path("frep-link") + "'").c_str()), 0);
  auto spelt = [&](const std::string& args) {
    return std::system(("cd '" + path("sub") + "' && ../frep-link " + args + " --no-progress >/dev/null 2>&1").c_str());
  };
  ASSERT_EQ(run("mesh s.hf -b 2 --res 33 -O a.ply --stl a.stl").code, 0);
  ASSERT_EQ(spelt("mesh --stl ../b.stl -O ../b.ply -g 32 ../sub/../s.hf -b -2,2"), 0);
  ASSERT_EQ(run("mesh s.vdb -O va.ply --stl va.stl").code, 0);
  ASSERT_EQ(spelt("mesh --stl ../vb.stl -O ../vb.ply ../sub/../s.vdb"), 0);
  for (const char* ext : {".ply", ".stl"}) {
    EXPECT_TRUE(readText(path(std::string("a") + ext)) == readText(path(std::string("b") + ext))) << ext << " of s.hf differs";
    EXPECT_TRUE(readText(path(std::string("va") + ext)) == readText(path(std::string("vb") + ext))) << ext << " of s.vdb differs";
  }
  const std::string stl = readText(path("a.stl")), vstl = readText(path("va.stl"));
  EXPECT_TRUE(contains(stl.substr(0, stl.find('\n')), "model hash ")) << stl.substr(0, 200);
  EXPECT_TRUE(contains(vstl.substr(0, vstl.find('\n')), "content hash ")) << vstl.substr(0, 200);
  EXPECT_FALSE(contains(vstl, "s.vdb")) << vstl.substr(0, 200);
  // A different job, or a different file, must differ (the same geometry: a[1] is unused, band 2).
  ASSERT_EQ(run("mesh s.hf -b 2 --res 33 -a 1 -O c.ply").code, 0);
  EXPECT_FALSE(readText(path("a.ply")) == readText(path("c.ply"))) << "-a 1 must show in the provenance";
  ASSERT_EQ(run("sample s.hf -b 1.5 --res 33 --band 2 -O t.vdb").code, 0);
  ASSERT_EQ(run("mesh t.vdb -O vc.ply").code, 0);
  EXPECT_FALSE(readText(path("va.ply")) == readText(path("vc.ply"))) << "another .vdb must show in the provenance";
}
