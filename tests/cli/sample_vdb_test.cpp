// frep sample writes a level set that OpenVDB reads back: -f at active voxels, metadata, transform.
// The only test file that includes OpenVDB (slow headers).
#include <openvdb/openvdb.h>

#include "frep_runner.h"

using namespace frep_cli_test;

namespace {

openvdb::FloatGrid::Ptr readGrid(const std::string& path) {
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  openvdb::GridPtrVecPtr grids = file.getGrids();
  file.close();
  EXPECT_EQ(grids->size(), 1u);
  return openvdb::gridPtrCast<openvdb::FloatGrid>(grids->front());
}

}  // namespace

TEST_F(FrepTest, SampleWritesALevelSetOfMinusF) {
  write("s.hf", kSphere);
  // Voxel 4 / 32 = 0.125: every grid point is dyadic, so f is exact in float.
  RunResult r = run("sample s.hf -b 2 --res 33 --band 3 -O s.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.find("wrote s.vdb: 33x33x33 voxels of 0.125, band 3 voxels\n") == 0) << r.out;
  EXPECT_NE(r.out.find("  NaN values 0\n"), std::string::npos) << r.out;
  EXPECT_EQ(listing(), "s.hf s.vdb s.vdb.report.json");

  openvdb::FloatGrid::Ptr grid = readGrid(path("s.vdb"));
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->getName(), "my_model");
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(grid->metaValue<std::string>("frep_sign"), "value = -f");
  EXPECT_EQ(grid->metaValue<std::string>("frep_object"), "my_model");
  EXPECT_EQ(grid->metaValue<std::string>("frep_operation"), "sample");
  EXPECT_EQ(grid->metaValue<std::string>("frep_model_hash").size(), 16u);
  EXPECT_NE(grid->metaValue<std::string>("frep_command").find("sample s.hf -b 2 --res 33 --band 3"),
            std::string::npos);
  EXPECT_EQ(grid->metaValue<int32_t>("frep_band_voxels"), 3);
  EXPECT_EQ(grid->metaValue<double>("frep_band"), 0.375);
  EXPECT_FALSE(grid->metaValue<std::string>("frep_version").empty());
  EXPECT_EQ(grid->background(), 0.375f);
  EXPECT_EQ(grid->voxelSize(), openvdb::Vec3d(0.125));
  EXPECT_EQ(grid->indexToWorld(openvdb::Coord(0, 0, 0)), openvdb::Vec3d(-2.0));

  // Every active voxel holds -f; the band reaches 3 voxels from the sphere of radius 1.
  size_t active = 0;
  for (auto it = grid->cbeginValueOn(); it; ++it) {
    openvdb::Vec3d p = grid->indexToWorld(it.getCoord());
    double f = 1.0 - p.x() * p.x() - p.y() * p.y() - p.z() * p.z();
    ASSERT_EQ(*it, float(-f)) << it.getCoord();
    ++active;
  }
  EXPECT_GT(active, 1000u);
  // The surface point (1, 0, 0) is active with value 0; centre and corner are ∓background.
  auto acc = grid->getConstAccessor();
  EXPECT_TRUE(acc.isValueOn(openvdb::Coord(24, 16, 16)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(24, 16, 16)), 0.0f);
  EXPECT_EQ(acc.getValue(openvdb::Coord(16, 16, 16)), -0.375f);
  EXPECT_FALSE(acc.isValueOn(openvdb::Coord(16, 16, 16)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(0, 0, 0)), 0.375f);
}

TEST_F(FrepTest, SampleHonoursParamsIsoAndGrid) {
  write("s.hf", kSphere);
  // Radius 1 + a[1] = 1.5, iso 1.25: the solid is 2.25 - r^2 >= 1.25, radius 1 again.
  RunResult r = run("sample s.hf -b 2 -g 32 -a 0.5 -i 1.25 -O s.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  openvdb::FloatGrid::Ptr grid = readGrid(path("s.vdb"));
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->metaValue<double>("frep_iso"), 1.25);
  EXPECT_EQ(grid->metaValue<std::string>("frep_params"), "0.5");
  auto acc = grid->getConstAccessor();
  EXPECT_TRUE(acc.isValueOn(openvdb::Coord(24, 16, 16)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(24, 16, 16)), 0.0f);
  EXPECT_EQ(acc.getValue(openvdb::Coord(25, 16, 16)), float(-(1.0 - 1.125 * 1.125)));
}

TEST_F(FrepTest, SampleLogsThroughSpdlogAtTheChosenLevel) {
  write("s.hf", kSphere);
  RunResult info = run("sample s.hf --res 16 -O a.vdb");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.err.find("frep: info: sampling 'my_model' on 16x16x16 voxels"), std::string::npos) << info.err;
  RunResult quiet = run("sample s.hf --res 16 -O b.vdb --log-level warn");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

TEST_F(FrepTest, SampleCountsNaNValues) {
  write("n.hf", "my_model(x[3], a[1]) { my_model = 0.5 - x[1]^0.5; }\n");
  RunResult r = run("sample n.hf -b 1 --res 16 -O n.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  // Voxels with x < 0 (8 of 16 columns) are NaN; NaN widens every interval, so all are sampled.
  EXPECT_NE(r.out.find("  NaN values 2048 (domain errors, stored as outside)\n"), std::string::npos) << r.out;
}
