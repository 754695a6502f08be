// ColourField: the colour of a model at a point (clamped to [0, 1], NaN as 0), the batch form
// equal to the point form for any thread count, and colourMesh's inward offset.
#include <gtest/gtest.h>

#include <cmath>

#include "frep/attributes/colour.h"

namespace frep {
namespace {

TEST(ColourField, ValuesAtPointsAreClampedChannels) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  ColourField colour({x, Expr(0.25) + y * Expr(0.5), sqrt(z) / (z - z)}, 3);
  double p[3] = {0.3, 0.5, 4.0};
  auto c = colour.at(p);
  EXPECT_FLOAT_EQ(c[0], 0.3f);
  EXPECT_FLOAT_EQ(c[1], 0.5f);
  EXPECT_EQ(c[2], 1.0f);  // 2/0 = inf, clamped
  double q[3] = {-2.0, 9.0, 0.0};
  c = colour.at(q);
  EXPECT_EQ(c[0], 0.0f);
  EXPECT_EQ(c[1], 1.0f);
  EXPECT_EQ(c[2], 0.0f);  // 0/0 = NaN -> 0
  EXPECT_THROW(ColourField({x, y}, 3), std::invalid_argument);
}

TEST(ColourField, BatchesEqualPointsForAnyThreadCount) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  ColourField colour({sin(x * Expr(3.0)) * Expr(0.5) + Expr(0.5), y * y, z - x}, 3);
  std::vector<std::array<double, 3>> points;
  for (int i = 0; i < 1000; ++i) points.push_back({std::sin(i * 0.7), std::cos(i * 0.3), 0.001 * i});
  auto one = colour.at(points, 1), two = colour.at(points, 2);
  ASSERT_EQ(one.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(one[i], two[i]);
    EXPECT_EQ(one[i], colour.at(points[i].data()));
  }
}

TEST(ColourField, MeshColoursAreTakenInsideAlongTheNormal) {
  Mesh m;
  m.positions = {{1, 0, 0}, {0, 1, 0}};
  m.normals = {{1, 0, 0}, {0, 1, 0}};
  ColourField colour({Expr::x(0), Expr::x(1), Expr(0.5)}, 3);
  colourMesh(m, colour, 0.25);
  ASSERT_EQ(m.colours.size(), 2u);
  EXPECT_FLOAT_EQ(m.colours[0][0], 0.75f);
  EXPECT_FLOAT_EQ(m.colours[1][1], 0.75f);
  EXPECT_FLOAT_EQ(m.colours[1][2], 0.5f);
}

}  // namespace
}  // namespace frep
