// The sparse sampler against a dense evaluation of the same grid.
#include <gtest/gtest.h>

#include <map>

#include "frep/evaluators/eval.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

Expr sphere(double cx, double cy, double cz, double r) {
  return r * r - square(X() - cx) - square(Y() - cy) - square(Z() - cz);
}
Expr boxMinusSphere() {
  Expr box = min(min(min(0.7 - X(), X() + 0.7), min(0.6 - Y(), Y() + 0.6)), min(0.5 - Z(), Z() + 0.5));
  return min(box, -sphere(0.3, 0.2, 0.4, 0.45));
}

struct Dense {
  GridSpec g;
  std::vector<double> f;
  double at(int i, int j, int k) const { return f[(size_t(i) * g.dims[1] + j) * g.dims[2] + k]; }
};

Dense dense(const TapePtr& tape, const GridSpec& g) {
  Dense d{g, {}};
  d.f.resize(size_t(g.dims[0]) * g.dims[1] * g.dims[2]);
  PointEvaluator pe;
  for (int i = 0; i < g.dims[0]; ++i)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int k = 0; k < g.dims[2]; ++k) {
        auto p = g.world(i, j, k);
        d.f[(size_t(i) * g.dims[1] + j) * g.dims[2] + k] = pe.eval(*tape, p.data());
      }
  return d;
}

using Key = std::array<int32_t, 3>;

// Checks the sampler's output voxel by voxel against the dense grid.
void checkAgainstDense(const Expr& model, int res, int band, int leafBlock = 2) {
  auto tape = Tape::compile(model, 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, res);
  SampleOptions opt;
  opt.bandVoxels = band;
  opt.leafBlock = leafBlock;
  SampleResult r = sample(tape, g, opt);
  Dense d = dense(tape, g);

  std::map<Key, const LeafBlock*> leaves;
  for (auto& l : r.leaves) leaves[l.origin] = &l;
  auto leafOf = [&](int i, int j, int k) -> const LeafBlock* {
    auto it = leaves.find(Key{i & ~7, j & ~7, k & ~7});
    return it == leaves.end() ? nullptr : it->second;
  };
  auto tileSign = [&](int i, int j, int k) -> int {
    for (auto& t : r.tiles)
      if (i >= t.origin[0] && i < t.origin[0] + t.size && j >= t.origin[1] && j < t.origin[1] + t.size &&
          k >= t.origin[2] && k < t.origin[2] + t.size)
        return t.inside ? 1 : -1;
    return 0;
  };

  size_t active = 0;
  for (int i = 0; i < g.dims[0]; ++i)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int k = 0; k < g.dims[2]; ++k) {
        double f = d.at(i, j, k);
        const LeafBlock* l = leafOf(i, j, k);
        if (!l) {
          int s = tileSign(i, j, k);
          ASSERT_NE(s, 0) << "voxel " << i << "," << j << "," << k << " in neither a leaf nor a tile";
          ASSERT_EQ(s > 0, f > 0) << "tile sign wrong at " << i << "," << j << "," << k;
          continue;
        }
        int off = leafOffset(i & 7, j & 7, k & 7);
        if (l->isActive(off)) {
          ++active;
          ASSERT_EQ(l->values[off], float(f)) << "band value differs from point evaluation";
        } else if (f != 0.0) {
          ASSERT_EQ(l->values[off] > 0, f > 0) << "inactive voxel has the wrong sign";
        }
      }
  EXPECT_GT(active, 0u);

  // Every sign change between grid neighbours lies in the band: all voxels within `band` of
  // both ends are active, hence every leaf the surface crosses is present.
  for (int i = 0; i < g.dims[0]; ++i)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int k = 0; k < g.dims[2]; ++k)
        for (int a = 0; a < 3; ++a) {
          int q[3] = {i, j, k};
          q[a] += 1;
          if (q[a] >= g.dims[a]) continue;
          if ((d.at(i, j, k) >= 0) == (d.at(q[0], q[1], q[2]) >= 0)) continue;
          for (int di = -band; di <= band; ++di)
            for (int dj = -band; dj <= band; ++dj)
              for (int dk = -band; dk <= band; ++dk) {
                int v[3] = {i + di, j + dj, k + dk};
                if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= g.dims[0] || v[1] >= g.dims[1] ||
                    v[2] >= g.dims[2])
                  continue;
                if (std::abs(v[a] - q[a]) > band) continue;
                const LeafBlock* l = leafOf(v[0], v[1], v[2]);
                ASSERT_NE(l, nullptr) << "surface leaf missing near " << i << "," << j << "," << k;
                ASSERT_TRUE(l->isActive(leafOffset(v[0] & 7, v[1] & 7, v[2] & 7)))
                    << "band voxel inactive near " << i << "," << j << "," << k;
              }
        }
}

}  // namespace

TEST(Sample, SphereMatchesDenseEvaluationAt128) { checkAgainstDense(sphere(0.05, -0.1, 0.02, 0.8), 128, 3); }

TEST(Sample, BoxMinusSphereMatchesDenseEvaluationAt128) { checkAgainstDense(boxMinusSphere(), 128, 3); }

TEST(Sample, NarrowBandOfOneVoxel) { checkAgainstDense(boxMinusSphere(), 70, 1); }

// The distance stores' 4^3 blocks (SampleOptions::leafBlock): the same guarantee, more points.
TEST(Sample, FourCubedBlocksKeepTheGuarantee) {
  checkAgainstDense(sphere(0.05, -0.1, 0.02, 0.8), 96, 3, 4);
  checkAgainstDense(boxMinusSphere(), 70, 1, 4);
}

TEST(Sample, CostFollowsTheSurface) {
  auto tape = Tape::compile(sphere(0, 0, 0, 0.8), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 256);
  SampleResult r = sample(tape, g);
  // The band of a sphere of radius ~102 voxels holds ~ 4 pi r^2 * 2 * 3.5 voxels (~0.9 M) of
  // the 16.8 M dense voxels; interval overestimation may add some, but never the volume.
  EXPECT_LT(double(r.stats.pointEvals), 0.12 * double(r.stats.denseEvals));
  EXPECT_GT(double(r.stats.pointEvals), 0.03 * double(r.stats.denseEvals));
}

TEST(Sample, DeterministicForAnyThreadCountAndRegionSplit) {
  auto tape = Tape::compile(boxMinusSphere(), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 96);
  SampleOptions serial;
  serial.threads = 1;
  SampleResult a = sample(tape, g, serial);
  SampleResult b = sample(tape, g);
  ASSERT_EQ(a.leaves.size(), b.leaves.size());
  for (size_t i = 0; i < a.leaves.size(); ++i) {
    EXPECT_EQ(a.leaves[i].origin, b.leaves[i].origin);
    EXPECT_EQ(a.leaves[i].values, b.leaves[i].values);
    EXPECT_EQ(a.leaves[i].active, b.leaves[i].active);
  }
  // Two bricks (x < 48 and x >= 48) give the same leaves as the whole grid.
  SampleOptions left, right;
  left.regionHi = {48, -1, -1};
  right.regionLo = {48, 0, 0};
  SampleResult l = sample(tape, g, left), rr = sample(tape, g, right);
  std::vector<LeafBlock> joined = l.leaves;
  joined.insert(joined.end(), rr.leaves.begin(), rr.leaves.end());
  ASSERT_EQ(joined.size(), a.leaves.size());
  for (size_t i = 0; i < joined.size(); ++i) {
    EXPECT_EQ(joined[i].origin, a.leaves[i].origin);
    EXPECT_EQ(joined[i].values, a.leaves[i].values);
    EXPECT_EQ(joined[i].active, a.leaves[i].active);
  }
}

TEST(Sample, RejectsBadInput) {
  auto tape = Tape::compile(sphere(0, 0, 0, 1), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 16);
  SampleOptions o;
  o.bandVoxels = -1;
  EXPECT_THROW(sample(tape, g, o), std::invalid_argument);
  SampleOptions unaligned;
  unaligned.regionLo = {3, 0, 0};
  EXPECT_THROW(sample(tape, g, unaligned), std::invalid_argument);
  for (int block : {0, 1, 3, 8}) {
    SampleOptions b;
    b.leafBlock = block;
    EXPECT_THROW(sample(tape, g, b), std::invalid_argument) << block;
  }
  auto tape4 = Tape::compile(sphere(0, 0, 0, 1) - square(Expr::x(3)), 4);
  EXPECT_THROW(sample(tape4, g), std::invalid_argument);
  EXPECT_THROW(GridSpec::fromBounds({1, 0, 0}, {0, 1, 1}, 16), std::invalid_argument);
}

TEST(Sample, BandZeroKeepsEverySignWithFewerEvaluations) {
  // Band 0 (the mesher of extremum models): only points of 2^3 blocks whose own box may hold a
  // zero are evaluated; every other point of a leaf keeps its certified sign as +-0.
  const double r = 0.77;
  auto tape = Tape::compile(sphere(0.01, 0.02, 0.03, r), 3);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 48);
  SampleOptions zero, one;
  zero.bandVoxels = 0;
  one.bandVoxels = 1;
  SampleResult a = sample(tape, g, zero), b = sample(tape, g, one);
  EXPECT_LT(double(a.stats.pointEvals), 0.8 * double(b.stats.pointEvals));
  size_t checked = 0;
  for (const LeafBlock& leaf : a.leaves)
    for (int i = 0; i < kLeafVoxels; ++i) {
      const int64_t x = leaf.origin[0] + (i >> 6), y = leaf.origin[1] + ((i >> 3) & 7), z = leaf.origin[2] + (i & 7);
      if (x >= g.dims[0] || y >= g.dims[1] || z >= g.dims[2]) continue;
      auto p = g.world(x, y, z);
      const double dx = p[0] - 0.01, dy = p[1] - 0.02, dz = p[2] - 0.03;
      const double f = r * r - dx * dx - dy * dy - dz * dz;
      EXPECT_EQ(!std::signbit(leaf.values[i]), f >= 0) << x << " " << y << " " << z;
      ++checked;
    }
  EXPECT_GT(checked, 10000u);
}

TEST(Sample, FourDimensionalModelWithFixedCoordinate) {
  // A 4D ball sliced at x[3] = 0.6 is a 3D ball of radius 0.8.
  auto tape = Tape::compile(1.0 - square(X()) - square(Y()) - square(Z()) - square(Expr::x(3)), 4);
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 33);
  SampleOptions o;
  o.fixedCoords = {0.6};
  SampleResult r = sample(tape, g, o);
  ASSERT_FALSE(r.leaves.empty());
  for (auto& l : r.leaves)
    for (int off = 0; off < kLeafVoxels; ++off) {
      if (!l.isActive(off)) continue;
      auto p = g.world(l.origin[0] + (off >> 6), l.origin[1] + ((off >> 3) & 7), l.origin[2] + (off & 7));
      double expect = 0.64 - p[0] * p[0] - p[1] * p[1] - p[2] * p[2];
      EXPECT_NEAR(l.values[off], expect, 1e-6);
    }
}
