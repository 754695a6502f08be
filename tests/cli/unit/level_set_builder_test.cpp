// io::LevelSetBuilder (what frep sample streams the farm's merge into) against writeLevelSet of
// the whole SampleResult: the same file, byte for byte, whatever the slabs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "frep/io/vdb_reader.h"
#include "frep/io/vdb_writer.h"
#include "frep/io/world_lattice.h"
#include "frep/expressions/expr.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// An empty file at a fresh path (the writers fill an existing file, as AtomicOutput's).
std::string emptyFile(const std::string& name) {
  const std::string path = "/tmp/frep_level_set_builder." + std::to_string(getpid()) + "." + name;
  std::ofstream(path).close();
  return path;
}

// A block with a ball cut out, on the world lattice: leaves on flat faces, edges and a curved
// pocket, and tiles inside and outside.
SampleResult bittenBlock() {
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr block = min(min(0.7 - abs(X), 0.6 - abs(Y)), 0.5 - abs(Z));
  Expr ball = 0.45 - sqrt(square(X - 0.3) + square(Y - 0.2) + square(Z - 0.4));
  GridSpec g = io::worldLatticeGrid("test", {-1, -1, -1}, {1, 1, 1}, 2.0 / 95);
  return sample(Tape::compile(min(block, -ball), 3), g);
}

}  // namespace

TEST(VdbLevelSetBuilder, SlabsOfAnySizeWriteTheBytesOfTheWholeResult) {
  SampleResult s = bittenBlock();
  ASSERT_GT(s.leaves.size(), 500u);
  ASSERT_GT(s.tiles.size(), 10u);
  for (io::VdbStore store : {io::VdbStore::Sdf, io::VdbStore::Raw, io::VdbStore::Fog}) {
    SCOPED_TRACE(io::storeName(store));
    io::VdbMetadata meta;
    meta.gridName = "bitten";
    meta.job = "test";
    meta.store = store;
    const std::string whole = emptyFile("whole.vdb");
    io::writeLevelSet(whole, s, meta);
    for (size_t slab : {size_t(1), size_t(97), s.leaves.size()}) {
      SCOPED_TRACE("slabs of " + std::to_string(slab) + " leaves");
      io::LevelSetBuilder b(s.grid, s.bandVoxels);
      b.addTiles(s.tiles);
      std::vector<LeafBlock> buffer;  // one buffer, refilled, as the farm's merge hands them over
      for (size_t at = 0; at < s.leaves.size(); at += slab) {
        buffer.assign(s.leaves.begin() + long(at), s.leaves.begin() + long(std::min(s.leaves.size(), at + slab)));
        b.addLeaves(buffer);
        for (LeafBlock& l : buffer) l = LeafBlock::cleared();  // the builder kept copies, not references
      }
      EXPECT_EQ(b.leaves(), s.leaves.size());
      const std::string streamed = emptyFile("streamed.vdb");
      b.write(streamed, meta);
      const std::string want = readAll(whole), got = readAll(streamed);
      EXPECT_GT(want.size(), 10000u);
      EXPECT_TRUE(want == got) << "the streamed file differs (" << got.size() << " bytes against " << want.size() << ")";
      std::remove(streamed.c_str());
    }
    std::remove(whole.c_str());
  }
}

// As the farm streams a sample: x-slab by x-slab, each slab's tiles (some reaching into later
// slabs) before its leaves; the same bytes as all the tiles first.
TEST(VdbLevelSetBuilder, EachXSlabsTilesBeforeItsLeavesWriteTheBytesOfTheWholeResult) {
  SampleResult s = bittenBlock();
  io::VdbMetadata meta;
  meta.gridName = "bitten";
  meta.job = "test";
  meta.store = io::VdbStore::Raw;
  const std::string whole = emptyFile("whole.vdb");
  io::writeLevelSet(whole, s, meta);
  bool tileReachesOn = false;
  for (int width : {8, 32}) {
    SCOPED_TRACE("x-slabs of " + std::to_string(width) + " voxels");
    io::LevelSetBuilder b(s.grid, s.bandVoxels);
    for (int x0 = 0; x0 < s.grid.dims[0]; x0 += width) {
      std::vector<Tile> tiles;
      std::vector<LeafBlock> leaves;
      for (const Tile& t : s.tiles)
        if (t.origin[0] >= x0 && t.origin[0] < x0 + width) {
          tiles.push_back(t);
          tileReachesOn = tileReachesOn || t.origin[0] + t.size > x0 + width;
        }
      for (const LeafBlock& l : s.leaves)
        if (l.origin[0] >= x0 && l.origin[0] < x0 + width) leaves.push_back(l);
      b.addTiles(tiles);
      b.addLeaves(leaves);
    }
    EXPECT_EQ(b.leaves(), s.leaves.size());
    const std::string streamed = emptyFile("xslabs.vdb");
    b.write(streamed, meta);
    EXPECT_TRUE(readAll(whole) == readAll(streamed)) << "the file built x-slab by x-slab differs";
    std::remove(streamed.c_str());
  }
  EXPECT_TRUE(tileReachesOn);  // some tile covered later slabs before their leaves came
  std::remove(whole.c_str());
}

TEST(VdbLevelSetBuilder, TilesAfterLeavesAndASecondWriteAreRefused) {
  SampleResult s = bittenBlock();
  io::LevelSetBuilder b(s.grid, s.bandVoxels);
  b.addTiles(s.tiles);
  b.addLeaves(s.leaves);
  EXPECT_THROW(b.addTiles(s.tiles), std::logic_error);  // a tile would overwrite the leaves it covers
  const std::string path = emptyFile("twice.vdb");
  b.write(path, io::VdbMetadata{});
  EXPECT_THROW(b.write(path, io::VdbMetadata{}), std::logic_error);
  std::remove(path.c_str());
}

// The builder fills tiles and prunes final leaves as the leaves come in x (io/src/vdb_writer.cpp,
// issue 35); leaves out of x order are built the old way (every tile, then every leaf, then one
// prune). On lattices whose origin is not on OpenVDB's 8-grid (every tile's faces cut leaves),
// both give the same bytes, for every store, slab by slab or whole.
TEST(VdbLevelSetBuilder, FillingAndPruningAsTheLeavesComeChangesNoByte) {
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr block = min(min(0.7 - abs(X), 0.6 - abs(Y)), 0.5 - abs(Z));
  Expr ball = 0.45 - sqrt(square(X - 0.3) + square(Y - 0.2) + square(Z - 0.4));
  const TapePtr tape = Tape::compile(min(block, -ball), 3);
  size_t misaligned = 0;
  for (const std::array<double, 3>& lo : {std::array<double, 3>{-1.03, -0.97, -1.1}, {-0.93, -1.13, -0.99}}) {
    GridSpec g = io::worldLatticeGrid("test", lo, {1.1, 1.0, 1.05}, 2.0 / 95);
    for (int a = 0; a < 3; ++a) misaligned += std::llround(g.origin[a] / g.voxel) % 8 != 0;
    const SampleResult s = sample(tape, g);
    ASSERT_GT(s.tiles.size(), 10u);
    SampleResult shuffled = s;  // the same leaves, not in x order: the old way
    for (size_t i = 0; i + 1 < shuffled.leaves.size(); i += 2) std::swap(shuffled.leaves[i], shuffled.leaves.back());
    ASSERT_FALSE(std::is_sorted(shuffled.leaves.begin(), shuffled.leaves.end(),
                                [](const LeafBlock& a, const LeafBlock& b) { return a.origin[0] < b.origin[0]; }));
    for (io::VdbStore store : {io::VdbStore::Sdf, io::VdbStore::Raw, io::VdbStore::Fog}) {
      SCOPED_TRACE(io::storeName(store));
      io::VdbMetadata meta;
      meta.gridName = "bitten";
      meta.store = store;
      const std::string old = emptyFile("old.vdb"), whole = emptyFile("whole.vdb"), slabs = emptyFile("slabs.vdb");
      io::writeLevelSet(old, shuffled, meta);
      io::writeLevelSet(whole, s, meta);
      io::LevelSetBuilder b(s.grid, s.bandVoxels);
      for (int x0 = 0; x0 < s.grid.dims[0]; x0 += 16) {
        std::vector<Tile> tiles;
        std::vector<LeafBlock> leaves;
        for (const Tile& t : s.tiles)
          if (t.origin[0] >= x0 && t.origin[0] < x0 + 16) tiles.push_back(t);
        for (const LeafBlock& l : s.leaves)
          if (l.origin[0] >= x0 && l.origin[0] < x0 + 16) leaves.push_back(l);
        b.addTiles(tiles);
        b.addLeaves(leaves);
      }
      b.write(slabs, meta);
      const std::string want = readAll(old);
      EXPECT_GT(want.size(), 10000u);
      EXPECT_TRUE(want == readAll(whole)) << "sorted leaves, filled and pruned as they come, differ";
      EXPECT_TRUE(want == readAll(slabs)) << "the streamed slabs differ";
      for (const std::string& p : {old, whole, slabs}) std::remove(p.c_str());
    }
  }
  EXPECT_GE(misaligned, 4u);  // the lattices cut OpenVDB's leaves
}

TEST(VdbLevelSetBuilder, LeavesBelowLeavesAlreadyPrunedAreRefused) {
  SampleResult s = bittenBlock();
  io::LevelSetBuilder b(s.grid, s.bandVoxels);
  b.addTiles(s.tiles);
  const size_t half = s.leaves.size() / 2;
  b.addLeaves(std::vector<LeafBlock>(s.leaves.begin() + long(half), s.leaves.end()));
  ASSERT_GT(s.leaves.back().origin[0] - s.leaves.front().origin[0], 16);
  EXPECT_THROW(b.addLeaves(std::vector<LeafBlock>(s.leaves.begin(), s.leaves.begin() + 1)), std::logic_error);
}

// spillLeaves: the finished leaves go to a temporary file as they come and the tree keeps their
// masks; the same bytes as the tree held whole, raw and sdf (the values as stored).
TEST(VdbLevelSetBuilder, LeavesWrittenOutAsTheyComeChangeNoByte) {
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr block = min(min(0.7 - abs(X), 0.6 - abs(Y)), 0.5 - abs(Z));
  Expr ball = 0.45 - sqrt(square(X - 0.3) + square(Y - 0.2) + square(Z - 0.4));
  const TapePtr tape = Tape::compile(min(block, -ball), 3);
  for (const std::array<double, 3>& lo : {std::array<double, 3>{-1.03, -0.97, -1.1}, {-1, -1, -1}}) {
    const SampleResult s = sample(tape, io::worldLatticeGrid("test", lo, {1.1, 1.0, 1.05}, 2.0 / 95));
    for (io::VdbStore store : {io::VdbStore::Sdf, io::VdbStore::Raw}) {
      SCOPED_TRACE(io::storeName(store));
      io::VdbMetadata meta;
      meta.gridName = "bitten";
      meta.store = store;
      meta.distanceValues = store == io::VdbStore::Sdf;
      const std::string whole = emptyFile("whole.vdb"), spilled = emptyFile("spilled.vdb");
      io::writeLevelSet(whole, s, meta);
      io::LevelSetBuilder b(s.grid, s.bandVoxels, /*spillLeaves=*/true);
      for (int x0 = 0; x0 < s.grid.dims[0]; x0 += 16) {
        std::vector<Tile> tiles;
        std::vector<LeafBlock> leaves;
        for (const Tile& t : s.tiles)
          if (t.origin[0] >= x0 && t.origin[0] < x0 + 16) tiles.push_back(t);
        for (const LeafBlock& l : s.leaves)
          if (l.origin[0] >= x0 && l.origin[0] < x0 + 16) leaves.push_back(l);
        b.addTiles(tiles);
        b.addLeaves(leaves);
      }
      EXPECT_GT(b.leavesWrittenOut(), 100u);  // the tree kept their masks only
      b.write(spilled, meta);
      const std::string want = readAll(whole), got = readAll(spilled);
      EXPECT_GT(want.size(), 10000u);
      EXPECT_EQ(got.size(), want.size());
      EXPECT_TRUE(want == got) << "the file with the leaves written out differs";
      for (const std::string& p : {whole, spilled}) std::remove(p.c_str());
    }
  }
}

TEST(VdbLevelSetBuilder, LeavesWrittenOutAreWrittenOnlyAsStored) {
  SampleResult s = bittenBlock();
  for (bool exact : {false, true}) {
    io::LevelSetBuilder b(s.grid, s.bandVoxels, /*spillLeaves=*/true);
    b.addTiles(s.tiles);
    b.addLeaves(s.leaves);
    io::VdbMetadata meta;
    meta.store = exact ? io::VdbStore::Sdf : io::VdbStore::Fog;  // sdf-exact or fog: values changed
    meta.distanceValues = !exact;
    const std::string path = emptyFile("refused.vdb");
    EXPECT_THROW(b.write(path, meta), std::logic_error);
    std::remove(path.c_str());
  }
}

// frep sample's grids start on OpenVDB's leaf lattice (io::leafAlignedGrid): the same lattice
// points, at most 7 more per axis on the low sides; every sampler leaf is then one OpenVDB leaf,
// which the writer copies whole (vdb_writer.cpp, addLeaf). Read back, every voxel holds the
// value and state the sampler gave it, and the space around the leaves its tiles' signs.
TEST(VdbLevelSetBuilder, LeafAlignedGridsWriteEverySampledVoxelAsItIs) {
  const double voxel = 2.0 / 95;
  const GridSpec g = io::worldLatticeGrid("test", {-0.93, -1.13, -0.99}, {1, 1, 1}, voxel);
  const GridSpec a = io::leafAlignedGrid(g);
  const int64_t gIndex[3] = {std::llround(g.origin[0] / voxel), std::llround(g.origin[1] / voxel),
                             std::llround(g.origin[2] / voxel)};
  int moved = 0;
  for (int k = 0; k < 3; ++k) {
    const int64_t aIndex = std::llround(a.origin[k] / voxel);
    EXPECT_EQ(aIndex % 8, 0) << k;
    EXPECT_LE(aIndex, gIndex[k]) << k;
    EXPECT_GT(aIndex, gIndex[k] - 8) << k;
    EXPECT_EQ(a.dims[k], g.dims[k] + (gIndex[k] - aIndex)) << k;  // the same far side
    moved += aIndex != gIndex[k];
  }
  EXPECT_GE(moved, 2);  // the box was off the leaf lattice: the test covers the move
  EXPECT_EQ(io::leafAlignedGrid(a).origin, a.origin);  // aligned stays
  EXPECT_EQ(io::leafAlignedGrid(a).dims, a.dims);

  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr block = min(min(0.7 - abs(X), 0.6 - abs(Y)), 0.5 - abs(Z));
  Expr ball = 0.45 - sqrt(square(X - 0.3) + square(Y - 0.2) + square(Z - 0.4));
  const SampleResult s = sample(Tape::compile(min(block, -ball), 3), a);
  ASSERT_GT(s.leaves.size(), 500u);
  io::VdbMetadata meta;
  meta.gridName = "bitten";
  meta.job = "test";
  meta.store = io::VdbStore::Raw;
  const std::string path = emptyFile("aligned.vdb");
  io::LevelSetBuilder b(s.grid, s.bandVoxels);
  b.addTiles(s.tiles);
  b.addLeaves(s.leaves);
  b.write(path, meta);
  const io::SampledVdb r = io::readSampledVdb(path, "bitten");
  std::remove(path.c_str());
  // The file's leaves by world index (the reader shifts its index space to its own origin).
  std::map<std::array<int64_t, 3>, const LeafBlock*> read;
  for (const LeafBlock& l : r.samples.leaves) {
    std::array<int64_t, 3> w;
    for (int k = 0; k < 3; ++k) w[k] = std::llround(r.samples.grid.origin[k] / voxel) + l.origin[k];
    read[w] = &l;
  }
  size_t compared = 0;
  for (const LeafBlock& l : s.leaves) {
    std::array<int64_t, 3> w;
    for (int k = 0; k < 3; ++k) w[k] = std::llround(a.origin[k] / voxel) + l.origin[k];
    bool anyActive = false;
    for (uint64_t word : l.active) anyActive = anyActive || word != 0;
    auto it = read.find(w);
    if (!anyActive) continue;  // pruned to a tile: its sign is checked by the sampler's own tests
    ASSERT_NE(it, read.end()) << "the leaf at world index " << w[0] << "," << w[1] << "," << w[2] << " is missing";
    for (int n = 0; n < kLeafVoxels; ++n) {
      ASSERT_EQ(it->second->isActive(n), l.isActive(n)) << n;
      if (l.isActive(n)) ASSERT_EQ(it->second->values[size_t(n)], l.values[size_t(n)]) << n;
      else ASSERT_EQ(it->second->values[size_t(n)] > 0, l.values[size_t(n)] > 0) << n;
      ++compared;
    }
  }
  EXPECT_GT(compared, 100000u);
}
