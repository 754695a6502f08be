// The band's signed distance (sampling/band_distance.h): exact for a plane and a ball's
// polynomial, close for an exact distance, a unit gradient at corners and edges, and the same
// values for any split of the grid into regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "frep/sampling/band_distance.h"

using namespace frep;

namespace {

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

Expr sphere(double r) { return r * r - square(X()) - square(Y()) - square(Z()); }
// A box minus a ball: concave and convex edges, corners, a slot-like dent.
Expr boxMinusBall() {
  Expr box = min(min(min(0.7 - X(), X() + 0.7), min(0.6 - Y(), Y() + 0.6)), min(0.5 - Z(), Z() + 0.5));
  return min(box, square(X() - 0.3) + square(Y() - 0.2) + square(Z() - 0.4) - 0.45 * 0.45);
}

SampleResult distanceOf(const TapePtr& tape, const GridSpec& g, int band, std::array<int32_t, 3> lo = {0, 0, 0},
                        std::array<int32_t, 3> hi = {-1, -1, -1}, int leafBlock = 2) {
  SampleOptions opt;
  opt.bandVoxels = band;
  opt.leafBlock = leafBlock;
  opt.regionLo = lo;
  opt.regionHi = hi;
  SampleResult r = sample(tape, g, opt);
  bandDistance(tape, g, opt, r);
  return r;
}

// The grid split into bricks of `brick` voxels, each computed on its own, leaves merged.
std::map<std::array<int32_t, 3>, LeafBlock> bricked(const TapePtr& tape, const GridSpec& g, int band, int brick,
                                                    int leafBlock) {
  std::map<std::array<int32_t, 3>, LeafBlock> out;
  for (int32_t x = 0; x < g.dims[0]; x += brick)
    for (int32_t y = 0; y < g.dims[1]; y += brick)
      for (int32_t z = 0; z < g.dims[2]; z += brick)
        for (LeafBlock& l : distanceOf(tape, g, band, {x, y, z}, {x + brick, y + brick, z + brick}, leafBlock).leaves)
          out[l.origin] = l;
  return out;
}

struct Voxel {
  float value;
  bool active;
};
std::map<std::array<int32_t, 3>, Voxel> voxels(const SampleResult& r) {
  std::map<std::array<int32_t, 3>, Voxel> out;
  for (const LeafBlock& l : r.leaves)
    for (int n = 0; n < kLeafVoxels; ++n) {
      const std::array<int32_t, 3> p = {l.origin[0] + (n >> 6), l.origin[1] + ((n >> 3) & 7), l.origin[2] + (n & 7)};
      if (p[0] < r.grid.dims[0] && p[1] < r.grid.dims[1] && p[2] < r.grid.dims[2])
        out[p] = {l.values[size_t(n)], l.isActive(n)};
    }
  return out;
}

TEST(BandDistance, PlaneIsExact) {
  // f linear: its interpolant is f itself, so every band value is the plane's distance.
  const double n[3] = {0.48, -0.6, 0.64};  // unit
  auto tape = Tape::compile(0.13 + n[0] * X() + n[1] * Y() + n[2] * Z(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 41);
  SampleResult r = distanceOf(tape, g, 3);
  size_t checked = 0;
  for (const auto& [p, v] : voxels(r)) {
    auto w = g.world(p[0], p[1], p[2]);
    const double exact = 0.13 + n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    if (std::fabs(exact) >= 2.5 * g.voxel) continue;  // well inside the band
    ASSERT_TRUE(v.active) << p[0] << "," << p[1] << "," << p[2];
    EXPECT_NEAR(v.value, exact, 1e-6) << p[0] << "," << p[1] << "," << p[2];
    ++checked;
  }
  EXPECT_GT(checked, 3000u);
}

// For both leaf blocks (SampleOptions::leafBlock): the halo decides on the sampler's blocks.
TEST(BandDistance, SameForAnyRegionSplit) {
  for (int leafBlock : {2, 4})
    for (const Expr& model : {sphere(0.62), boxMinusBall()}) {
      SCOPED_TRACE("leaf block " + std::to_string(leafBlock));
      auto tape = Tape::compile(model, 3);
      GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 45);
      SampleResult whole = distanceOf(tape, g, 3, {0, 0, 0}, {-1, -1, -1}, leafBlock);
      std::map<std::array<int32_t, 3>, const LeafBlock*> ref;
      for (const LeafBlock& l : whole.leaves) ref[l.origin] = &l;
      for (int brick : {8, 16, 24}) {
        auto split = bricked(tape, g, 3, brick, leafBlock);
        ASSERT_EQ(split.size(), ref.size()) << "brick " << brick;
        for (const auto& [o, l] : split) {
          ASSERT_TRUE(ref.count(o));
          EXPECT_EQ(0, std::memcmp(l.values.data(), ref[o]->values.data(), sizeof l.values)) << "brick " << brick;
          EXPECT_EQ(l.active, ref[o]->active) << "brick " << brick;
        }
      }
    }
}

TEST(BandDistance, UnitGradientNearTheSurface) {
  // |grad| of the stored values by central differences, at voxels within a voxel of the surface.
  auto tape = Tape::compile(boxMinusBall(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64);
  auto v = voxels(distanceOf(tape, g, 3));
  std::vector<double> norms;
  for (const auto& [p, x] : v) {
    if (!x.active || std::fabs(x.value) > g.voxel) continue;
    double g2 = 0;
    bool ok = true;
    for (int a = 0; a < 3 && ok; ++a) {
      auto lo = p, hi = p;
      --lo[a], ++hi[a];
      auto l = v.find(lo), h = v.find(hi);
      ok = l != v.end() && h != v.end() && l->second.active && h->second.active;
      if (ok) g2 += std::pow((h->second.value - l->second.value) / (2 * g.voxel), 2);
    }
    if (ok) norms.push_back(std::sqrt(g2));
  }
  ASSERT_GT(norms.size(), 1000u);
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  EXPECT_NEAR(norms[norms.size() / 2], 1.0, 0.02);
}

TEST(BandDistance, BallPolynomialIsExact) {
  // r^2 - |x|^2 is quadratic along its straight gradient lines: its expansion's zero is the
  // ball's surface, up to rounding, wherever every neighbour was evaluated.
  const double radius = 0.62;
  auto tape = Tape::compile(sphere(radius), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64);
  double worst = 0;
  size_t checked = 0;
  for (const auto& [p, v] : voxels(distanceOf(tape, g, 3))) {
    auto w = g.world(p[0], p[1], p[2]);
    const double exact = radius - std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (!v.active || std::fabs(exact) > 2 * g.voxel) continue;  // the band's edge has one-sided differences
    worst = std::max(worst, std::fabs(v.value - exact));
    ++checked;
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_LT(worst, 1e-5 * g.voxel);
}

TEST(BandDistance, ExactDistanceKept) {
  // f already a distance (r - |x|): the estimate stays within a hundredth of a voxel of it.
  const double radius = 0.62;
  auto tape = Tape::compile(radius - sqrt(square(X()) + square(Y()) + square(Z())), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64);
  double worst = 0;
  for (const auto& [p, v] : voxels(distanceOf(tape, g, 3))) {
    auto w = g.world(p[0], p[1], p[2]);
    const double exact = radius - std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (v.active && std::fabs(exact) < 2 * g.voxel) worst = std::max(worst, std::fabs(v.value - exact));
  }
  EXPECT_LT(worst, 0.01 * g.voxel);
}

}  // namespace
