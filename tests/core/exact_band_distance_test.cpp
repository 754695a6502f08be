// The band's exact distance to the samples' piecewise-linear zero set
// (sampling/exact_band_distance.h): exact for a plane, near the analytic distance of a ball and
// a box, a distance's properties (1-Lipschitz, no further than an edge's interpolated zero), a
// unit gradient, and the same bytes for any split of the grid into regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "frep/sampling/exact_band_distance.h"

using namespace frep;

namespace {

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

Expr sphere(double r) { return r * r - square(X()) - square(Y()) - square(Z()); }
// A box [-a, a] x [-b, b] x [-c, c] moved by (0.013, -0.021, 0.007), as the min of its slabs.
const double kBox[3] = {0.5, 0.4, 0.3}, kShift[3] = {0.013, -0.021, 0.007};
Expr box() {
  Expr s[3] = {X() - kShift[0], Y() - kShift[1], Z() - kShift[2]};
  return min(min(min(kBox[0] - s[0], s[0] + kBox[0]), min(kBox[1] - s[1], s[1] + kBox[1])),
             min(kBox[2] - s[2], s[2] + kBox[2]));
}
double boxDistance(const std::array<double, 3>& p) {  // positive inside
  double q[3], outside = 0, inside = -1e9;
  for (int a = 0; a < 3; ++a) {
    q[a] = std::fabs(p[a] - kShift[a]) - kBox[a];
    outside += std::pow(std::max(q[a], 0.0), 2);
    inside = std::max(inside, q[a]);
  }
  return -(std::sqrt(outside) + std::min(inside, 0.0));
}
Expr boxMinusBall() {
  Expr b = min(min(min(0.7 - X(), X() + 0.7), min(0.6 - Y(), Y() + 0.6)), min(0.5 - Z(), Z() + 0.5));
  return min(b, square(X() - 0.3) + square(Y() - 0.2) + square(Z() - 0.4) - 0.45 * 0.45);
}

SampleResult exactOf(const TapePtr& tape, const GridSpec& g, int band, std::array<int32_t, 3> lo = {0, 0, 0},
                     std::array<int32_t, 3> hi = {-1, -1, -1}, int leafBlock = 2) {
  SampleOptions opt;
  opt.bandVoxels = band;
  opt.leafBlock = leafBlock;
  opt.regionLo = lo;
  opt.regionHi = hi;
  SampleResult r = sample(tape, g, opt);
  exactBandDistance(tape, g, opt, r);
  return r;
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

// Median and largest |stored - exact| in voxels over active voxels whose exact distance is
// below `reach` voxels, away from the grid's faces (where the zero set is cut off).
std::array<double, 2> errors(const SampleResult& r, const std::function<double(const std::array<double, 3>&)>& exact,
                             double reach) {
  std::vector<double> e;
  for (const auto& [p, v] : voxels(r)) {
    const double d = exact(r.grid.world(p[0], p[1], p[2]));
    if (!v.active || std::fabs(d) > reach * r.grid.voxel) continue;
    bool nearFace = false;
    for (int a = 0; a < 3; ++a) nearFace = nearFace || p[a] < reach || p[a] + reach >= r.grid.dims[a] - 1;
    if (nearFace) continue;
    e.push_back(std::fabs(v.value - d) / r.grid.voxel);
  }
  if (e.size() < 1000) return {1e9, 1e9};
  std::sort(e.begin(), e.end());
  return {e[e.size() / 2], e.back()};
}

TEST(ExactBandDistance, PlaneIsExact) {
  // f linear: its piecewise-linear interpolant is f itself, the zero set the plane.
  const double n[3] = {0.48, -0.6, 0.64};  // unit
  auto tape = Tape::compile(0.13 + n[0] * X() + n[1] * Y() + n[2] * Z(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 41);
  auto e = errors(
      exactOf(tape, g, 3), [&](const auto& w) { return 0.13 + n[0] * w[0] + n[1] * w[1] + n[2] * w[2]; }, 2.9);
  EXPECT_LT(e[1], 1e-6);
}

// For both leaf blocks (SampleOptions::leafBlock; frep sample's distance stores take 4).
TEST(ExactBandDistance, SameForAnyRegionSplit) {
  for (int leafBlock : {2, 4})
    for (const Expr& model : {sphere(0.62), boxMinusBall(), box()}) {
      SCOPED_TRACE("leaf block " + std::to_string(leafBlock));
      auto tape = Tape::compile(model, 3);
      GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 45);
      SampleResult whole = exactOf(tape, g, 3, {0, 0, 0}, {-1, -1, -1}, leafBlock);
      std::map<std::array<int32_t, 3>, const LeafBlock*> ref;
      for (const LeafBlock& l : whole.leaves) ref[l.origin] = &l;
      for (int brick : {8, 16, 24}) {
        std::map<std::array<int32_t, 3>, LeafBlock> split;
        for (int32_t x = 0; x < g.dims[0]; x += brick)
          for (int32_t y = 0; y < g.dims[1]; y += brick)
            for (int32_t z = 0; z < g.dims[2]; z += brick)
              for (LeafBlock& l : exactOf(tape, g, 3, {x, y, z}, {x + brick, y + brick, z + brick}, leafBlock).leaves)
                split[l.origin] = l;
        ASSERT_EQ(split.size(), ref.size()) << "brick " << brick;
        for (const auto& [o, l] : split) {
          ASSERT_TRUE(ref.count(o));
          EXPECT_EQ(0, std::memcmp(l.values.data(), ref[o]->values.data(), sizeof l.values)) << "brick " << brick;
          EXPECT_EQ(l.active, ref[o]->active) << "brick " << brick;
        }
      }
    }
}

TEST(ExactBandDistance, BallAndBoxNearTheirDistances) {
  // A ball's interpolated zero set lies within about 3h^2 / 8r of the sphere (f's second
  // derivative over a Kuhn tetrahedron's long diagonal): second order, so half as many voxels
  // at twice the resolution; a box's faces are exact, its edges and corners cut by the cells
  // they cross.
  const double radius = 0.62;
  double previous = 1e9;
  for (int n : {32, 64}) {
    GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, n);
    auto ball = errors(
        exactOf(Tape::compile(sphere(radius), 3), g, 3),
        [&](const auto& w) { return radius - std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]); }, 2.9);
    const double sag = 3 * g.voxel / (8 * radius);  // voxels
    EXPECT_LT(ball[0], sag) << n << " median, voxels";
    EXPECT_LT(ball[1], 2 * sag) << n << " largest, voxels";
    EXPECT_LT(ball[0], 0.6 * previous) << n << " median against the coarser grid's";
    previous = ball[0];
    auto cube = errors(exactOf(Tape::compile(box(), 3), g, 3), boxDistance, 2.9);
    std::printf("voxel %.4f: ball median %.2e, largest %.2e; box median %.2e, largest %.2e (voxels)\n", g.voxel,
                ball[0], ball[1], cube[0], cube[1]);
    EXPECT_LT(cube[0], 1e-5) << n << " median, voxels";
    EXPECT_LT(cube[1], 1.0) << n << " largest (at the edges), voxels";
  }
}

TEST(ExactBandDistance, IsADistanceToTheInterpolatedZeros) {
  // 1-Lipschitz between neighbours, and no further from a voxel than the interpolated zero on
  // an edge from it to a neighbour of the other sign (a point of the zero set).
  auto tape = Tape::compile(boxMinusBall(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 48);
  SampleOptions opt;
  SampleResult raw = sample(tape, g, opt);
  auto f = voxels(raw);
  auto v = voxels(exactOf(tape, g, 3));
  size_t edges = 0;
  for (const auto& [p, x] : v) {
    if (!x.active) continue;
    for (int a = 0; a < 3; ++a) {
      auto q = p;
      ++q[a];
      auto y = v.find(q);
      if (y == v.end() || !y->second.active) continue;
      EXPECT_LE(std::fabs(x.value - y->second.value), g.voxel * (1 + 1e-6));
      const double fp = f.at(p).value, fq = f.at(q).value;
      if ((fp >= 0) != (fq >= 0)) {
        const double t = fp / (fp - fq);
        EXPECT_LE(std::fabs(x.value), t * g.voxel * (1 + 1e-6) + 1e-12);
        EXPECT_LE(std::fabs(y->second.value), (1 - t) * g.voxel * (1 + 1e-6) + 1e-12);
        ++edges;
      }
    }
  }
  EXPECT_GT(edges, 1000u);
}

TEST(ExactBandDistance, UnitGradientNearTheSurface) {
  // |grad| of the stored values by central differences, within a voxel of the surface, where
  // the estimate of the default store has its worst errors (convex and concave creases).
  auto tape = Tape::compile(boxMinusBall(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64);
  auto v = voxels(exactOf(tape, g, 3));
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

}  // namespace
