// frep sample writes a level set that OpenVDB reads back: -f at active voxels, metadata, transform.
// The only test file that includes OpenVDB (slow headers).
#include <openvdb/openvdb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "frep/io/vdb_grid.h"
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

TEST_F(FrepTest, SampleStoreRawWritesALevelSetOfMinusF) {
  write("s.hf", kSphere);
  // Voxel 4 / 32 = 0.125: every grid point is dyadic, so f is exact in float.
  RunResult r = run("sample s.hf -b 2 --res 33 --band 3 --store raw -O s.vdb");
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
  EXPECT_EQ(grid->metaValue<std::string>("frep_store"), "raw");
  EXPECT_EQ(grid->metaValue<std::string>("frep_job"),
            "sample object=my_model params= iso=0 map= voxel=0.125 lattice=-16,-16,-16:16,16,16 band=3 store=raw");
  EXPECT_EQ(grid->metaValue<std::string>("frep_source"), "s.hf");
  EXPECT_EQ(grid->metaValue<int32_t>("frep_band_voxels"), 3);
  EXPECT_EQ(grid->metaValue<double>("frep_band"), 0.375);
  EXPECT_FALSE(grid->metaValue<std::string>("frep_version").empty());
  EXPECT_EQ(grid->background(), 0.375f);
  EXPECT_EQ(grid->voxelSize(), openvdb::Vec3d(0.125));
  // The world lattice: index (i, j, k) is world (i, j, k) * voxel; the box -2..2 is -16..16.
  EXPECT_EQ(grid->indexToWorld(openvdb::Coord(0, 0, 0)), openvdb::Vec3d(0.0));
  EXPECT_EQ(grid->indexToWorld(openvdb::Coord(-16, -16, -16)), openvdb::Vec3d(-2.0));

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
  EXPECT_TRUE(acc.isValueOn(openvdb::Coord(8, 0, 0)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(8, 0, 0)), 0.0f);
  EXPECT_EQ(acc.getValue(openvdb::Coord(0, 0, 0)), -0.375f);
  EXPECT_FALSE(acc.isValueOn(openvdb::Coord(0, 0, 0)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(-16, -16, -16)), 0.375f);
}

TEST_F(FrepTest, SampleHonoursParamsIsoAndGrid) {
  write("s.hf", kSphere);
  // Radius 1 + a[1] = 1.5, iso 1.25: the solid is 2.25 - r^2 >= 1.25, radius 1 again.
  RunResult r = run("sample s.hf -b 2 -g 32 -a 0.5 -i 1.25 --store raw -O s.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  openvdb::FloatGrid::Ptr grid = readGrid(path("s.vdb"));
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->metaValue<double>("frep_iso"), 1.25);
  EXPECT_EQ(grid->metaValue<std::string>("frep_params"), "0.5");
  auto acc = grid->getConstAccessor();
  EXPECT_TRUE(acc.isValueOn(openvdb::Coord(8, 0, 0)));
  EXPECT_EQ(acc.getValue(openvdb::Coord(8, 0, 0)), 0.0f);
  EXPECT_EQ(acc.getValue(openvdb::Coord(9, 0, 0)), float(-(1.0 - 1.125 * 1.125)));
}

TEST_F(FrepTest, SampleWritesASignedDistanceByDefault) {
  write("s.hf", kSphere);
  RunResult r = run("sample s.hf -b 2 --res 33 -O s.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  openvdb::FloatGrid::Ptr grid = readGrid(path("s.vdb"));
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(grid->metaValue<std::string>("frep_store"), "sdf");
  EXPECT_EQ(grid->background(), 0.375f);
  // The sphere's distance |p| - 1 (the sampler's -f is 1 - |p|^2: twice as steep at the surface).
  size_t active = 0;
  for (auto it = grid->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3d p = grid->indexToWorld(it.getCoord());
    if (std::abs(*it) < 0.25) EXPECT_NEAR(*it, p.length() - 1.0, 0.01) << it.getCoord();
    ++active;
  }
  EXPECT_GT(active, 1000u);
  // The workers' distance (core band_distance.h), with its bound, not the master's mesh trip.
  EXPECT_NE(grid->metaValue<std::string>("frep_distance").find("second-order estimate"), std::string::npos);
}

TEST_F(FrepTest, DefaultStoreIsTheSameBytesInProcessAndOnOneOrTwoWorkers) {
  // Each brick's distance reads a halo from its neighbours: a block with a ball and blended
  // edges, on bricks of 16 (two workers) and 64 (in-process, one worker), gives one file.
  write("b.hf",
        "my_model(x[3], a[1]) {\n  array c[3];\n  c = [-0.6, -0.6, -0.4];\n  blk = hfBlock(x, c, 1.2, 1.2, 0.8);\n"
        "  ball = 0.16 - (x[1] - 0.5)^2 - x[2]^2 - (x[3] - 0.4)^2;\n  my_model = hfBlendUni(blk, ball, 0.05, 0.1, 0.1);\n}\n");
  const std::string box = " -b -1,-1,-1,1,1,1 --res 40 ";
  ASSERT_EQ(run("sample b.hf" + box + "--workers 0 -O w0.vdb").code, 0);
  ASSERT_EQ(run("sample b.hf" + box + "--workers 1 -O w1.vdb").code, 0);
  RunResult r = run("sample b.hf" + box + "--workers 2 --brick 16 -O w2.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string bytes = readText(path("w0.vdb"));
  EXPECT_GT(bytes.size(), 10000u);
  EXPECT_TRUE(bytes == readText(path("w1.vdb")));
  EXPECT_TRUE(bytes == readText(path("w2.vdb")));
}

TEST_F(FrepTest, SdfExactStoreIsTheBoxDistanceWhereTheEstimateIsNot) {
  // A box written the HyperFun way (hfBlock: R-function intersections of slabs) is not a
  // distance, so the default store's per-brick estimate falls short; sdf-exact is the exact
  // distance to the samples' piecewise-linear zero set, computed per brick on the workers with
  // a halo of the band's width: the same bytes in-process, on 1 and 2 workers, any brick size.
  write("b.hf",
        "my_model(x[3], a[1]) {\n  array c[3];\n  c = [-0.5, -0.5, -0.5];\n"
        "  my_model = hfBlock(x, c, 1, 1, 1);\n}\n");
  const std::string box = " -b 1 --res 41 ";
  RunResult r = run("sample b.hf" + box + "--store sdf-exact --workers 0 -O e0.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(run("sample b.hf" + box + "--store sdf-exact --workers 1 -O e1.vdb").code, 0);
  ASSERT_EQ(run("sample b.hf" + box + "--store sdf-exact --workers 2 --brick 16 -O e2.vdb").code, 0);
  ASSERT_EQ(run("sample b.hf" + box + "--store sdf-exact --workers 2 --brick 24 -O e3.vdb").code, 0);
  ASSERT_EQ(run("sample b.hf" + box + "--workers 0 -O d.vdb").code, 0);
  const std::string bytes = readText(path("e0.vdb"));
  EXPECT_TRUE(bytes == readText(path("e1.vdb")));
  EXPECT_TRUE(bytes == readText(path("e2.vdb")));
  EXPECT_TRUE(bytes == readText(path("e3.vdb")));
  EXPECT_NE(readGrid(path("e0.vdb"))->metaValue<std::string>("frep_distance").find("piecewise-linear zero set"),
            std::string::npos);
  // The exact distance to the cube [-0.5, 0.5]^3.
  auto cube = [](const openvdb::Vec3d& p) {
    const double qx = std::abs(p.x()) - 0.5, qy = std::abs(p.y()) - 0.5, qz = std::abs(p.z()) - 0.5;
    const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0), oz = std::max(qz, 0.0);
    return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max(qx, std::max(qy, qz)), 0.0);
  };
  // The error's median and 95th percentile in the band, in voxels. The interpolated zero set
  // chamfers the edges, so the largest errors of sdf-exact are there; the estimate's reach the
  // faces as well (f there is an R-function of slabs, not a distance).
  auto errors = [&](const std::string& file) {
    openvdb::FloatGrid::Ptr grid = readGrid(path(file));
    std::vector<double> e;
    for (auto it = grid->cbeginValueOn(); it; ++it)
      if (std::abs(*it) < 0.9 * grid->background()) e.push_back(std::abs(*it - cube(grid->indexToWorld(it.getCoord()))));
    std::sort(e.begin(), e.end());
    const double v = grid->voxelSize().x();
    return e.size() < 1000 ? std::array<double, 2>{1e9, 1e9} : std::array<double, 2>{e[e.size() / 2] / v, e[e.size() * 95 / 100] / v};
  };
  const auto exact = errors("e0.vdb"), estimate = errors("d.vdb");
  std::printf("cube at 41^3, error in voxels: sdf-exact median %.2e, 95th percentile %.3f; sdf %.2e, %.3f\n", exact[0],
              exact[1], estimate[0], estimate[1]);
  EXPECT_LT(exact[0], 0.01) << "sdf-exact's median, voxels";
  EXPECT_LT(exact[0], estimate[0]) << "medians";
  EXPECT_LT(exact[1], estimate[1]) << "95th percentiles";
}

TEST_F(FrepTest, SdfExactAgreesWithTheOldGlobalRebuild) {
  // The store before 2026-12-06 (OpenVDB's levelSetRebuild of the merged samples on the master,
  // io::signedDistanceGrid, applied here to the raw store's grid) against the workers' exact
  // distance: both are distances to nearly the same triangles (OpenVDB meshes the cells by its
  // own rule, not Kuhn's tetrahedra), so they agree to a small fraction of a voxel on a sphere,
  // a hfBlock cube and the chair, except within a voxel of edges, where the two triangulations
  // cut a cell's corner differently.
  write("b.hf",
        "my_model(x[3], a[1]) {\n  array c[3];\n  c = [-0.5, -0.5, -0.5];\n"
        "  my_model = hfBlock(x, c, 1, 1, 1);\n}\n");
  write("s.hf", kSphere);
  struct Case {
    std::string model, box;
    double median, p95;  // voxels
  };
  const Case cases[] = {{"s.hf", " -b 1.5 --res 48 ", 0.03, 0.06},
                        {"b.hf", " -b 1 --res 41 ", 0.01, 0.75},
                        {std::string(FREP_SOURCE_DIR) + "/examples/chair.hf", " -b -1.5,-1.5,-0.5,1.5,1.5,2.5 --res 96 ",
                         0.01, 0.2}};
  for (const Case& c : cases) {
    ASSERT_EQ(run("sample " + c.model + c.box + "--store sdf-exact --workers 0 -O x.vdb").code, 0) << c.model;
    ASSERT_EQ(run("sample " + c.model + c.box + "--store raw --workers 0 -O r.vdb").code, 0) << c.model;
    openvdb::FloatGrid::Ptr exact = readGrid(path("x.vdb")), raw = readGrid(path("r.vdb"));
    const int band = raw->metaValue<int32_t>("frep_band_voxels");
    openvdb::FloatGrid::Ptr old = frep::io::signedDistanceGrid(*raw, band);
    openvdb::FloatGrid::ConstAccessor o = old->getConstAccessor();
    const double v = exact->voxelSize().x(), reach = 0.9 * exact->background();
    std::vector<double> d;
    for (auto it = exact->cbeginValueOn(); it; ++it)
      if (std::abs(*it) < reach && std::abs(o.getValue(it.getCoord())) < reach)
        d.push_back(std::abs(*it - o.getValue(it.getCoord())) / v);
    ASSERT_GT(d.size(), 1000u) << c.model;
    std::sort(d.begin(), d.end());
    std::printf("%s: sdf-exact against the old rebuild, voxels: median %.2e, 95th percentile %.3f, largest %.3f\n",
                c.model.c_str(), d[d.size() / 2], d[d.size() * 95 / 100], d.back());
    EXPECT_LT(d[d.size() / 2], c.median) << c.model;
    EXPECT_LT(d[d.size() * 95 / 100], c.p95) << c.model;
    // A true distance: |grad| (central differences) within a voxel of the surface, median within
    // 2 % of 1; its 95th percentile of ||grad| - 1| printed beside the old store's.
    auto unitGradient = [&](const openvdb::FloatGrid& g) {
      openvdb::FloatGrid::ConstAccessor a = g.getConstAccessor();
      std::vector<double> n;
      for (auto it = g.cbeginValueOn(); it; ++it) {
        if (std::abs(*it) > v) continue;
        double g2 = 0;
        bool ok = true;
        for (int ax = 0; ax < 3 && ok; ++ax) {
          openvdb::Coord lo = it.getCoord(), hi = it.getCoord();
          lo[ax] -= 1, hi[ax] += 1;
          ok = a.isValueOn(lo) && a.isValueOn(hi);
          g2 += std::pow((a.getValue(hi) - a.getValue(lo)) / (2 * v), 2);
        }
        if (ok) n.push_back(std::sqrt(g2));
      }
      std::sort(n.begin(), n.end());
      std::vector<double> dev;
      for (double x : n) dev.push_back(std::abs(x - 1));
      std::sort(dev.begin(), dev.end());
      return n.size() < 100 ? std::array<double, 2>{0, 1e9} : std::array<double, 2>{n[n.size() / 2], dev[dev.size() * 95 / 100]};
    };
    const auto mine = unitGradient(*exact), before = unitGradient(*old);
    std::printf("  |grad| median %.4f, 95th percentile of ||grad| - 1| %.4f (old rebuild: %.4f, %.4f)\n", mine[0],
                mine[1], before[0], before[1]);
    EXPECT_NEAR(mine[0], 1.0, 0.02) << c.model;
  }
}

TEST_F(FrepTest, SampleBoxIsRoundedOutwardToTheWorldLattice) {
  write("s.hf", kSphere);
  // Voxel 0.125 (-g 32 over 4); -1.95..2.05 rounds to -2..2.125 (index -16..17).
  RunResult r = run("sample s.hf -b -1.95,-1.95,-1.95,2.05,2.05,2.05 -g 32 --store raw -O s.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.find("wrote s.vdb: 34x34x34 voxels of 0.125") == 0) << r.out;
  openvdb::FloatGrid::Ptr grid = readGrid(path("s.vdb"));
  EXPECT_EQ(grid->metaValue<openvdb::Vec3i>("frep_box_index_min"), openvdb::Vec3i(-16));
  EXPECT_EQ(grid->metaValue<openvdb::Vec3i>("frep_box_index_max"), openvdb::Vec3i(17));
  EXPECT_EQ(grid->metaValue<openvdb::Vec3d>("frep_box_min"), openvdb::Vec3d(-2.0));
  EXPECT_EQ(grid->metaValue<openvdb::Vec3d>("frep_box_max"), openvdb::Vec3d(2.125));
  // The surface point (1, 0, 0) is lattice index (8, 0, 0) whatever the box.
  EXPECT_EQ(grid->getConstAccessor().getValue(openvdb::Coord(8, 0, 0)), 0.0f);
}

TEST_F(FrepTest, SampleBytesDoNotDependOnHowTheCommandIsSpelt) {
  write("s.hf", kSphere);
  ASSERT_EQ(run("sample s.hf -b 2 --res 33 -O a.vdb").code, 0);
  // Another spelling of the model's path, options in another order, -g for the same lattice,
  // another argv[0] (a symlink to the binary).
  ASSERT_EQ(std::system(("mkdir -p '" + path("sub") + "' && ln -s '" FREP_BINARY "' '" + path("frep-link") + "'").c_str()), 0);
  std::string cmd = "cd '" + path("sub") + "' && ../frep-link sample -O ../b.vdb --band 3 -g 32 ../sub/../s.hf -b -2,2 "
                    "--no-progress >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(readText(path("a.vdb")) == readText(path("b.vdb"))) << "output bytes differ";
  ASSERT_EQ(run("sample s.hf -b 2 --res 33 --band 2 -O c.vdb").code, 0);
  EXPECT_FALSE(readText(path("a.vdb")) == readText(path("c.vdb"))) << "a different job must differ";
}

TEST_F(FrepTest, SampleFogVolumeIsADensityGrid) {
  write("s.hf", kSphere);
  ASSERT_EQ(run("sample s.hf -b 2 --res 33 --store fog -O f.vdb").code, 0);
  openvdb::FloatGrid::Ptr grid = readGrid(path("f.vdb"));
  EXPECT_EQ(grid->getName(), "density");
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_FOG_VOLUME);
  EXPECT_EQ(grid->metaValue<std::string>("frep_object"), "my_model");
  auto acc = grid->getConstAccessor();
  EXPECT_EQ(acc.getValue(openvdb::Coord(0, 0, 0)), 1.0f);
  EXPECT_EQ(acc.getValue(openvdb::Coord(16, 16, 16)), 0.0f);
  RunResult bad = run("sample s.hf --res 16 --store density -O x.vdb");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--store"), std::string::npos) << bad.err;
}

TEST_F(FrepTest, SampleLogsThroughSpdlogAtTheChosenLevel) {
  write("s.hf", kSphere);
  RunResult info = run("sample s.hf --res 16 -O a.vdb");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.err.find("frep: info: sampling 'my_model' on 17x17x17 voxels"), std::string::npos) << info.err;
  RunResult quiet = run("sample s.hf --res 16 -O b.vdb --log-level warn");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

TEST_F(FrepTest, SampleCountsNaNValues) {
  write("n.hf", "my_model(x[3], a[1]) { my_model = 0.5 - x[1]^0.5; }\n");
  RunResult r = run("sample n.hf -b 1 --res 16 -O n.vdb");
  ASSERT_EQ(r.code, 0) << r.err;
  // The slab 0 <= x <= 0.25 is cut by the box's y and z faces, so the lattice grows by the band
  // and a voxel (4 points) on every side: -12..12 in steps of 2/15, then down to OpenVDB's leaf
  // lattice: -16..12 (29 points). Voxels with x < 0 (16 of 29 columns) are NaN, also outside
  // the box (the cut keeps a NaN a NaN); NaN widens every interval, so all are sampled: 16 * 29 * 29.
  EXPECT_NE(r.out.find("wrote n.vdb: 29x29x29 voxels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  NaN values 13456 (domain errors, stored as outside)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("the solid is cut by the box's faces y-min, y-max, z-min, z-max"), std::string::npos) << r.err;
}

TEST_F(FrepTest, DefaultBrickKeepsTwoWorkersBusyWithTheSameBytes) {
  // 64^3 points (-b 0..63 with -g 63: voxel 1): one brick of 64 would idle a worker.
  write("s.hf", "my_model(x[3], a[1]) { my_model = 400 - (x[1]-30)^2 - (x[2]-30)^2 - (x[3]-30)^2; }\n");
  RunResult a = run("sample s.hf -b 0,0,0,63,63,63 -g 63 --workers 2 --no-progress -O a.vdb");
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_TRUE(a.out.find("wrote a.vdb: 64x64x64 voxels") == 0) << a.out;
  EXPECT_NE(a.out.find("bricks 8 (8 computed"), std::string::npos) << a.out;  // bricks of 32
  RunResult b = run("sample s.hf -b 0,0,0,63,63,63 -g 63 --workers 2 --brick 64 --no-progress -O b.vdb");
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_NE(b.out.find("bricks 1 (1 computed"), std::string::npos) << b.out;
  EXPECT_TRUE(readText(path("a.vdb")) == readText(path("b.vdb"))) << "output bytes differ";
}
