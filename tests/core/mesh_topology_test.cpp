// The topology a mesh field is built on (geometry/mesh_topology.h and MeshField's
// construction): welding by equal coordinates in order of first appearance, edge uses sorted
// by key, and the orientation walk over a fine mesh with scattered flipped triangles (a flip
// moves the corners, so the walk must find a flipped triangle's edges where they went).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/mesh_models.h"
#include "frep/geometry/distance_fields.h"
#include "geometry/mesh_topology.h"

namespace frep {
namespace {

TEST(MeshTopology, WeldsEqualCoordinatesInOrderOfFirstAppearance) {
  // -0 equals 0; the first appearance's coordinates are kept.
  const std::vector<double> xyz = {1, 2, 3, 0.0, 0, 1, 1, 2, 3, -0.0, 0, 1, 5, 5, 5, 1, 2, 3.0000000000000004};
  std::vector<double> welded;
  const std::vector<uint32_t> ids = mesh_topology::weldVertices(xyz, welded);
  EXPECT_EQ(ids, (std::vector<uint32_t>{0, 1, 0, 1, 2, 3}));
  ASSERT_EQ(welded.size(), 12u);
  EXPECT_FALSE(std::signbit(welded[3]));  // the first appearance: +0
  EXPECT_EQ(welded[11], 3.0000000000000004);
  std::vector<double> bad = {0, 0, NAN}, out;
  EXPECT_THROW(mesh_topology::weldVertices(bad, out), std::invalid_argument);
  bad = {0, INFINITY, 0};
  EXPECT_THROW(mesh_topology::weldVertices(bad, out), std::invalid_argument);
}

TEST(MeshTopology, EdgeUsesAreSortedByKeyThenUse) {
  const std::vector<uint32_t> tris = {0, 1, 2, 2, 1, 3, 3, 1, 0};
  const mesh_topology::EdgeUses e = mesh_topology::edgeUsesOf(tris);
  ASSERT_EQ(e.key.size(), 9u);
  std::map<uint64_t, std::vector<uint32_t>> want;  // the same by a map
  for (uint32_t u = 0; u < 9; ++u) want[mesh_topology::edgeKey(tris[u], tris[u / 3 * 3 + (u + 1) % 3])].push_back(u);
  size_t i = 0;
  for (const auto& [key, uses] : want)
    for (uint32_t u : uses) {
      EXPECT_EQ(e.key[i], key);
      EXPECT_EQ(e.use[i], u);
      ++i;
    }
}

// A torus of nu x nv quads, a fraction of its triangles given clockwise.
mesh_models::TorusSoup scrambledTorus(int nu, int nv, double flipped, unsigned seed) {
  mesh_models::TorusSoup s = mesh_models::torusSoup(0.8, 0.3, nu, nv);
  std::mt19937 rng(seed);
  std::bernoulli_distribution flip(flipped);
  for (size_t t = 0; t < s.tris.size(); t += 3)
    if (flip(rng)) std::swap(s.tris[t + 1], s.tris[t + 2]);
  return s;
}

TEST(MeshTopology, OrientationWalkFixesScatteredFlips) {
  const auto clean = scrambledTorus(40, 20, 0.0, 1);
  const MeshField reference(clean.xyz, clean.tris, "torus");
  for (double fraction : {0.3, 0.7, 1.0}) {
    const auto mixed = scrambledTorus(40, 20, fraction, 2);
    const MeshField f(mixed.xyz, mixed.tris, "mixed torus");
    ASSERT_TRUE(f.check().closed());
    // Every edge run once each way: one orientation throughout.
    std::map<std::pair<uint32_t, uint32_t>, int> runs;
    const std::vector<uint32_t>& t = f.triangles();
    for (size_t i = 0; i < t.size(); i += 3)
      for (int c = 0; c < 3; ++c) ++runs[{t[i + c], t[i + (c + 1) % 3]}];
    for (const auto& [edge, n] : runs) {
      ASSERT_EQ(n, 1) << "fraction " << fraction << ": edge " << edge.first << "-" << edge.second << " run twice";
      ASSERT_EQ(runs.count({edge.second, edge.first}), 1u);
    }
    EXPECT_NEAR(f.volume(), reference.volume(), 1e-12);
    EXPECT_GT(f.volume(), 0.0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> box(-1.2, 1.2);
    for (int i = 0; i < 500; ++i) {
      const double p[3] = {box(rng), box(rng), 0.3 * box(rng)};
      ASSERT_NEAR(f.value(p), reference.value(p), 1e-12);
    }
  }
}

TEST(MeshTopology, OpenAndNonManifoldEdgesAreCountedInKeyOrder) {
  // Two triangles of a square (4 open edges, one shared) and a third on the shared edge.
  const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1};
  const MeshField f(xyz, {0, 1, 2, 0, 2, 3, 2, 0, 4}, "fin");
  EXPECT_EQ(f.check().nonManifoldEdges, 1u);  // 0-2, used three times
  EXPECT_EQ(f.check().openEdges, 6u);
  ASSERT_EQ(f.check().firstOpen.size(), 5u);
  EXPECT_EQ(f.check().firstOpen[0], (std::array<uint32_t, 2>{0, 1}));
  EXPECT_EQ(f.check().firstOpen[1], (std::array<uint32_t, 2>{0, 3}));
  EXPECT_EQ(f.check().firstOpen[2], (std::array<uint32_t, 2>{0, 4}));
  EXPECT_EQ(f.check().firstOpen[3], (std::array<uint32_t, 2>{1, 2}));
  EXPECT_EQ(f.check().firstOpen[4], (std::array<uint32_t, 2>{2, 3}));
}

}  // namespace
}  // namespace frep
