// The core pieces behind `frep mesh input.vdb` and the master's lean merge, without a binary:
// meshSamples (core/include/frep/meshing/mesh_grid.h) against meshGrid on the same signs, and
// mergePiecesReleasing (core/include/frep/meshing/mesh_merge.h) against mergePieces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/mesh_checks.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_grid.h"
#include "frep/meshing/mesh_merge.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

using namespace frep;
namespace mc = mesh_checks;

namespace {

TapePtr torusTape() {  // a torus R 0.6, r 0.25, tilted so that no face is grid aligned
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Expr u = 0.8 * x + 0.6 * z, w = -0.6 * x + 0.8 * z;
  Expr q = sqrt(square(u) + square(y)) - 0.6;
  return Tape::compile(0.0625 - square(q) - square(w), 3);
}

std::vector<mc::Tri> tris(const Mesh& m) {
  std::vector<mc::Tri> t;
  for (const auto& a : m.triangles) t.push_back({a[0], a[1], a[2]});
  return t;
}

bool sameMesh(const Mesh& a, const Mesh& b) {
  return a.keys == b.keys && a.positions == b.positions && a.normals == b.normals && a.triangles == b.triangles &&
         a.stats.rootEvals == b.stats.rootEvals && a.stats.cellsVisited == b.stats.cellsVisited;
}

}  // namespace

TEST(MeshSamples, SameEdgesAsTheModelMesherAndClosed) {
  TapePtr tape = torusTape();
  GridSpec grid = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 50);
  SampleOptions so;
  so.bandVoxels = 2;
  SampleResult s = sample(tape, grid, so);
  SampledMesh sm = meshSamples(s);
  Mesh model = meshGrid(tape, grid);
  EXPECT_EQ(sm.incompleteCells, 0u);
  ASSERT_GT(sm.mesh.triangles.size(), 1000u);
  EXPECT_EQ(sm.mesh.keys, model.keys);  // the same crossed edges
  EXPECT_EQ(sm.mesh.stats.cellsCrossed, model.stats.cellsCrossed);
  EXPECT_EQ(sm.mesh.triangles.size(), model.triangles.size());
  double worst = 0;
  for (size_t i = 0; i < model.positions.size(); ++i) {
    worst = std::max(worst, mc::norm(mc::sub(sm.mesh.positions[i], model.positions[i])));
    ASSERT_GT(mc::dot(sm.mesh.normals[i], model.normals[i]), 0.9) << i;
  }
  EXPECT_LT(worst, grid.voxel);  // the same edge; grazing edges let the linear root slide along it
  // ... while every vertex stays near the surface: first-order distance |f| / |grad f|.
  GradientEvaluator ge;
  double far = 0;
  for (const auto& p : sm.mesh.positions) {
    double g[3];
    const double f = ge.eval(*tape, p.data(), g);
    far = std::max(far, std::abs(f) / std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]));
  }
  EXPECT_LT(far, 0.1 * grid.voxel);
  EXPECT_EQ(mc::checkEdgePairs(tris(sm.mesh), sm.mesh.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(tris(sm.mesh), sm.mesh.positions.size()), 0);
  EXPECT_EQ(mc::selfIntersections(sm.mesh.positions, tris(sm.mesh)), 0u);
  const double volume = 2 * M_PI * M_PI * 0.6 * 0.25 * 0.25;
  EXPECT_NEAR(mc::enclosedVolume(sm.mesh.positions, tris(sm.mesh)), volume, 0.01 * volume);

  // Threads do not change anything.
  SampledMeshOptions serial;
  serial.threads = 1;
  EXPECT_TRUE(sameMesh(meshSamples(s, serial).mesh, sm.mesh));
}

TEST(MeshSamples, CrossedCellsWithAnInactiveCornerAreCountedAndLeftOut) {
  TapePtr tape = torusTape();
  GridSpec grid = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 34);
  SampleResult s = sample(tape, grid, SampleOptions{});
  const size_t full = meshSamples(s).mesh.triangles.size();
  // Deactivate one active voxel that has a neighbour of the other sign.
  bool done = false;
  for (LeafBlock& l : s.leaves) {
    for (int n = 0; n < kLeafVoxels && !done; ++n) {
      if (!l.isActive(n) || (n & 7) == 7) continue;
      if (std::signbit(l.values[n]) != std::signbit(l.values[n + 1]) && l.isActive(n + 1)) {
        l.active[n >> 6] &= ~(uint64_t(1) << (n & 63));
        done = true;
      }
    }
    if (done) break;
  }
  ASSERT_TRUE(done);
  SampledMesh sm = meshSamples(s);
  EXPECT_GT(sm.incompleteCells, 0u);
  EXPECT_LT(sm.mesh.triangles.size(), full);
  EXPECT_NE(mc::checkEdgePairs(tris(sm.mesh), sm.mesh.positions.size()), "");  // a hole, reported
}

TEST(MergePiecesReleasing, EqualsMergePiecesForAnySplitAndOrder) {
  TapePtr tape = torusTape();
  GridSpec grid = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 45);
  std::vector<MeshPiece> pieces;
  for (int32_t x = 0; x < grid.dims[0] - 1; x += 16)
    for (int32_t y = 0; y < grid.dims[1] - 1; y += 16)
      for (int32_t z = 0; z < grid.dims[2] - 1; z += 16)
        pieces.push_back(meshRegion(tape, grid, {x, y, z}, {x + 16, y + 16, z + 16}));
  const Mesh reference = mergePieces(pieces);
  std::mt19937 rng(7);
  for (int round = 0; round < 3; ++round) {
    std::vector<MeshPiece> copy = pieces;
    std::shuffle(copy.begin(), copy.end(), rng);
    Mesh lean = mergePiecesReleasing(copy, round != 1);  // with and without trimming the heap
    EXPECT_TRUE(sameMesh(lean, reference)) << round;
    EXPECT_EQ(lean.stats.gradientEvals, reference.stats.gradientEvals);
    for (const MeshPiece& p : copy) EXPECT_TRUE(p.vertices.empty() && p.triangles.empty());
  }
  // Both merge entry points share their code, so the stitched mesh is also checked against one
  // region meshed whole (a single piece, nothing to stitch; its counters differ by the split).
  const Mesh whole = meshGrid(tape, grid);
  EXPECT_TRUE(whole.keys == reference.keys && whole.positions == reference.positions &&
              whole.normals == reference.normals && whole.triangles == reference.triangles);
  // A malformed piece is refused as mergePieces refuses it.
  std::vector<MeshPiece> bad = pieces;
  auto it = std::find_if(bad.begin(), bad.end(), [](const MeshPiece& p) { return p.vertices.size() >= 2; });
  ASSERT_NE(it, bad.end());
  std::swap(it->vertices[0], it->vertices[1]);
  EXPECT_THROW(mergePiecesReleasing(bad), std::invalid_argument);
}
