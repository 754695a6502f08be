// Geometric types of -x (Pasko-Survey): the values of each type, the per-picture mappings, the
// spectral colours, and the errors.
#include "geometric_types.h"

#include <gtest/gtest.h>

#include "exit_codes.h"

using namespace frep::cli;

TEST(GeometricTypes, ValuesAndMappings) {
  GeometricRequest q;
  q.tFrames = 3, q.tRange = "0,1";
  q.vCells = 2, q.vRange = "-1,1";
  q.cLevels = 3, q.cRange = "0,0.5";
  const GeometricTypes g = parseGeometricTypes("X,t,Y,Z,V,c,0.25", q, true);
  EXPECT_EQ(g.coordinate[GeometricTypes::T], 1);
  EXPECT_EQ(g.coordinate[GeometricTypes::V], 4);
  EXPECT_EQ(g.sectionCoordinate(), 5);
  EXPECT_FALSE(g.has(GeometricTypes::W));
  EXPECT_EQ(g.t, (std::vector<double>{0, 0.5, 1}));
  EXPECT_EQ(g.v, (std::vector<double>{-1, 1}));
  EXPECT_EQ(g.sections, (std::vector<double>{0, 0.25, 0.5}));
  EXPECT_TRUE(g.colourSections);
  EXPECT_EQ(g.mapping(0.5, -1, 7, 0.25), "X,0.5,Y,Z,-1,0.25,0.25");
  // Without -x, --t-frames sweeps x[4].
  q = GeometricRequest{};
  q.tFrames = 2;
  EXPECT_EQ(parseGeometricTypes("", q, true).mapping(0.25, 0, 0, 0), "X,Y,Z,0.25");
  EXPECT_EQ(parseGeometricTypes("", GeometricRequest{}, true).mapping(1, 2, 3, 4), "");
  q = GeometricRequest{};
  q.gValues = "3,1,2";
  const GeometricTypes group = parseGeometricTypes("X,Y,G,Z", q, false);
  EXPECT_EQ(group.sections, (std::vector<double>{3, 1, 2}));
  EXPECT_FALSE(group.colourSections);
}

TEST(GeometricTypes, SpectralColoursRunFromRedToViolet) {
  EXPECT_EQ(spectralColour(0), (std::array<double, 3>{0.9, 0, 0}));
  const auto mid = spectralColour(0.5), end = spectralColour(1);
  EXPECT_GT(mid[1], mid[0]);
  EXPECT_GT(mid[1], mid[2]);
  EXPECT_GT(end[2], end[1]);
  EXPECT_GT(end[0], end[1]);  // violet: blue with some red
  EXPECT_EQ(framePath("a/b.png", 7, 10), "a/b_0007.png");
  EXPECT_EQ(framePath("a.d/b", 1, 2), "a.d/b_0001");
  EXPECT_EQ(framePath("b.png", 0, 1), "b.png");
}

TEST(GeometricTypes, ErrorsNameTheOption) {
  auto message = [](const std::string& mapping, const GeometricRequest& q) {
    try {
      parseGeometricTypes(mapping, q, true);
    } catch (const CliError& e) {
      EXPECT_EQ(e.code, kExitBadArgs);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  GeometricRequest q;
  EXPECT_EQ(message("X,Y,Z,T", q), "--t-frames: the T coordinate needs the number of frames (1 or more)");
  q.tFrames = 2;
  EXPECT_EQ(message("X,Y,Z,1", q), "--t-frames: give T in -x for the swept coordinate (e.g. -x X,Y,Z,T)");
  EXPECT_EQ(message("X,Y,Z,V,V", GeometricRequest{}), "-x/--map: geometric type V is given twice in 'X,Y,Z,V,V'");
  EXPECT_EQ(message("X,Y,C,G", GeometricRequest{}), "-x/--map: C and G both make a union of sections; give one of them");
  GeometricRequest bad;
  bad.wCells = 10001;
  EXPECT_EQ(message("X,Y,Z,W", bad), "--w-range/--w-cells: expected a count from 1 to 10000, got 10001");
  bad = GeometricRequest{};
  bad.cRange = "0,1,2";
  EXPECT_EQ(message("X,Y,Z,C", bad), "--c-range/--c-levels: expected first,last, got '0,1,2'");
  EXPECT_EQ(message("X,Y,Z,G", GeometricRequest{}), "--g-values: the G coordinate needs its values, e.g. --g-values 0,0.5,1");
}
