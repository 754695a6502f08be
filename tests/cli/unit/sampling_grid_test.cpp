// Grids from --res and -g: point counts, voxel size and origin.
#include "sampling_grid.h"

#include <gtest/gtest.h>

#include <cmath>

#include "exit_codes.h"

using namespace frep::cli;

TEST(SamplingGrid, ResCountsPointsAlongTheLongestAxis) {
  Box box = parseBounds("-b", "-1,-2,-1,1,2,1");
  frep::GridSpec g = makeGrid(box, 3, resolutionFrom(41, "", 128));
  EXPECT_DOUBLE_EQ(g.voxel, 0.1);
  EXPECT_EQ(g.dims, (std::array<int32_t, 3>{21, 41, 21}));
  EXPECT_EQ(g.origin, (std::array<double, 3>{-1, -2, -1}));
}

TEST(SamplingGrid, HfpCellsGiveNPlusOnePoints) {
  frep::GridSpec g = makeGrid(parseBounds("-b", "10"), 3, resolutionFrom(0, "30", 128));
  EXPECT_EQ(g.dims, (std::array<int32_t, 3>{31, 31, 31}));
  // Per-axis cells: cubic voxels of the coarsest axis, every axis still covered.
  frep::GridSpec h = makeGrid(parseBounds("-b", "1"), 3, resolutionFrom(0, "4,8,2", 128));
  EXPECT_DOUBLE_EQ(h.voxel, 1.0);
  EXPECT_EQ(h.dims, (std::array<int32_t, 3>{3, 3, 3}));
}

TEST(SamplingGrid, TwoAxesLeaveTheThirdSingle) {
  frep::GridSpec g = makeGrid(parseBounds("-b", "0,0,0,2,1,0.5"), 2, resolutionFrom(0, "", 5));
  EXPECT_DOUBLE_EQ(g.voxel, 0.5);
  EXPECT_EQ(g.dims, (std::array<int32_t, 3>{5, 3, 1}));
}

TEST(SamplingGrid, ResolutionErrors) {
  try {
    resolutionFrom(100, "30", 128);
    FAIL();
  } catch (const CliError& e) {
    EXPECT_EQ(e.code, kExitBadArgs);
    EXPECT_STREQ(e.what(), "--res and -g/--grid: give one of them, not both");
  }
  try {
    resolutionFrom(1, "", 128);
    FAIL();
  } catch (const CliError& e) {
    EXPECT_STREQ(e.what(), "--res: expected an integer from 2 to 65536, got 1");
  }
}

TEST(SamplingGrid, ResMatchesTheCoreGridAndStaysInsideTheBox) {
  Box box = parseBounds("-b", "0,0,0,1,0.35,0.3");
  frep::GridSpec g = makeGrid(box, 3, resolutionFrom(11, "", 128));
  frep::GridSpec core = frep::GridSpec::fromBounds(box.lo, box.hi, 11);
  EXPECT_EQ(g.dims, core.dims);
  EXPECT_EQ(g.voxel, core.voxel);
  EXPECT_EQ(g.origin, core.origin);
  EXPECT_EQ(g.dims, (std::array<int32_t, 3>{11, 4, 4}));  // 0.35 / 0.1 -> 3 steps; 0.3 / 0.1 -> 3
}

TEST(SamplingGrid, SampleRoundsTheBoxOutwardToTheWorldLattice) {
  Box box = parseBounds("-b", "0,0,0,1,0.35,0.3");
  frep::GridSpec g = makeWorldLatticeGrid(box, resolutionFrom(11, "", 128));
  EXPECT_DOUBLE_EQ(g.voxel, makeGrid(box, 3, resolutionFrom(11, "", 128)).voxel);
  EXPECT_EQ(g.dims, (std::array<int32_t, 3>{11, 5, 4}));  // 0.35 -> 0.4; 0.3 is on the lattice
  EXPECT_EQ(g.origin, (std::array<double, 3>{0, 0, 0}));
  // Off the lattice below: -0.05 -> -0.1, 0.13 -> 0.1; every origin is a whole number of voxels.
  frep::GridSpec h = makeWorldLatticeGrid(parseBounds("-b", "-0.05,-0.2,0.13,0.95,0.2,0.5"), resolutionFrom(11, "", 128));
  EXPECT_DOUBLE_EQ(h.voxel, 0.1);
  EXPECT_EQ(h.dims, (std::array<int32_t, 3>{12, 5, 5}));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(h.origin[a] / h.voxel, std::round(h.origin[a] / h.voxel), 1e-9) << a;
  EXPECT_NEAR(h.origin[0], -0.1, 1e-15);
  EXPECT_NEAR(h.origin[2], 0.1, 1e-15);
  // hfp's -g 30 -b 10: +-10 are on the lattice, 31 points as makeGrid.
  frep::GridSpec c = makeWorldLatticeGrid(parseBounds("-b", "10"), resolutionFrom(0, "30", 128));
  EXPECT_EQ(c.dims, makeGrid(parseBounds("-b", "10"), 3, resolutionFrom(0, "30", 128)).dims);
  EXPECT_EQ(c.dims, (std::array<int32_t, 3>{31, 31, 31}));
  // OpenVDB's 32-bit index: a box 1e6 from the origin at a voxel of 1e-4 is refused.
  try {
    makeWorldLatticeGrid(parseBounds("-b", "1000000,1000000,1000000,1000000.1,1000000.1,1000000.1"), resolutionFrom(1001, "", 128));
    FAIL() << "expected an error";
  } catch (const CliError& e) {
    EXPECT_EQ(e.code, kExitBadArgs);
    EXPECT_NE(std::string(e.what()).find("-b/--bounds"), std::string::npos) << e.what();
  }
}

// Derived sizes must be finite and positive: a box of 1e-310 underflows the voxel (exit 2), and
// the widest finite box gives a finite voxel.
TEST(SamplingGrid, DerivedVoxelSizesAreFiniteAndPositive) {
  try {
    makeGrid(parseBounds("-b", "1e-310"), 3, resolutionFrom(0, "", 128));
    ADD_FAILURE() << "a voxel that underflows was accepted";
  } catch (const CliError& e) {
    EXPECT_EQ(e.code, kExitBadArgs);
    EXPECT_NE(std::string(e.what()).find("not a positive finite number"), std::string::npos) << e.what();
  }
  frep::GridSpec g = makeGrid(parseBounds("-b", "8e307"), 3, resolutionFrom(0, "", 128));
  EXPECT_TRUE(std::isfinite(g.voxel) && g.voxel > 0);
}
