// The mesher (mesh.h) on models with known answers: watertight and consistently oriented,
// no degenerate triangles, Euler characteristic, volume and area against formulas, vertices on
// the surface, outward normals, and the same mesh whatever the split into regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdio>
#include <random>

#include "core/mesh_checks.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/primitives/ops.h"

using namespace frep;
namespace mc = mesh_checks;
using namespace mesh_models;

namespace {

struct Checked {
  Mesh mesh;
  long euler = 0;
  int components = 0;
  double volume = 0, area = 0, minArea = 0;
};

Checked meshAndCheck(const Expr& model, const GridSpec& g, int brick = 0, const MeshOptions& opt = {}) {
  Checked c;
  TapePtr tape = Tape::compile(model, 3);
  c.mesh = meshGrid(tape, g, opt, brick);
  const Mesh& m = c.mesh;
  EXPECT_GT(m.triangles.size(), 0u);
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  c.euler = mc::eulerCharacteristic(m.triangles, m.positions.size());
  c.components = mc::components(m.triangles, m.positions.size());
  c.volume = mc::enclosedVolume(m.positions, m.triangles);
  c.area = mc::surfaceArea(m.positions, m.triangles);
  c.minArea = mc::minTriangleArea(m.positions, m.triangles);
  // No degenerate triangles: vertices stay endGuard (1e-3) of an edge away from grid points,
  // which bounds every triangle's area below by 0.4 * endGuard^2 voxel^2 (docs/mesh.md).
  EXPECT_GT(c.minArea, 0.3 * 1e-6 * g.voxel * g.voxel);
  // Every vertex used by some triangle.
  EXPECT_EQ(mc::selfIntersections(m.positions, m.triangles), 0u);
  std::vector<char> used(m.positions.size(), 0);
  for (const auto& t : m.triangles)
    for (uint32_t v : t) used[v] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);
  return c;
}

// Printed for the record (docs/mesh.md quotes them).
void figures(const char* name, const Checked& c, double volume, double area) {
  std::printf("[figures] %-36s V %7zu F %7zu  volume %.6f (err %+.3f%%)  area %.6f (err %+.3f%%)  min area %.2e\n",
              name, c.mesh.positions.size(), c.mesh.triangles.size(), c.volume, 100 * (c.volume / volume - 1),
              c.area, 100 * (c.area / area - 1), c.minArea);
}

// Newton projection onto {f = 0}: every vertex converges to |f| < 1e-10 within half a voxel.
// (Feature vertices sit on creases, where Newton's steps alternate between the two branches of
// a min/max and settle more slowly: callers pass a looser fTol for them.)
void checkVerticesOnSurface(const Expr& model, const Mesh& m, double voxel, double fTol = 1e-10) {
  TapePtr tape = Tape::compile(model, 3);
  GradientEvaluator ge;
  double worstMove = 0, worstStart = 0;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    std::array<double, 3> x = m.positions[i], g;
    double f0 = ge.eval(*tape, x.data(), g.data());
    double f = f0;
    for (int it = 0; it < 8 && std::abs(f) > 1e-13; ++it) {
      double gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
      ASSERT_GT(gg, 0) << "vertex " << i;
      for (int c = 0; c < 3; ++c) x[c] -= f * g[c] / gg;
      f = ge.eval(*tape, x.data(), g.data());
    }
    EXPECT_LT(std::abs(f), fTol) << "vertex " << i;
    worstMove = std::max(worstMove, mc::norm(mc::sub(x, m.positions[i])));
    worstStart = std::max(worstStart, std::abs(f0));
  }
  EXPECT_LT(worstMove, 0.5 * voxel);
}

// A certificate that works on creases too: within 0.49 voxel of the vertex (itself, +-normal,
// or one of 26 grid directions) there is a point with f >= 0 and one with f < 0, so the segment
// between them, inside that ball, crosses the surface: the vertex is within half a voxel of it.
void checkVerticesNearSurface(const Expr& model, const Mesh& m, double voxel) {
  TapePtr tape = Tape::compile(model, 3);
  PointEvaluator pe;
  EXPECT_EQ(mc::verticesFarFromSurface(m.positions, m.normals, 0.49 * voxel,
                                       [&](const mc::Vec3& p) { return pe.eval(*tape, p.data()); }),
            0u);
}

void checkNormals(const Mesh& m, const std::function<mc::Vec3(const mc::Vec3&)>& outward) {
  double worst = 2;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    mc::Vec3 n = outward(m.positions[i]);
    double len = mc::norm(n);
    worst = std::min(worst, mc::dot(m.normals[i], n) / len);
    EXPECT_NEAR(mc::norm(m.normals[i]), 1.0, 1e-12);
  }
  EXPECT_GT(worst, 0.9);
}

void expectIdentical(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_TRUE(a.keys == b.keys);
  EXPECT_TRUE(a.positions == b.positions);  // bit for bit
  EXPECT_TRUE(a.normals == b.normals);
  EXPECT_TRUE(a.triangles == b.triangles);
}

}  // namespace

TEST(Mesh, TablesGiveOneClosedSurfacePerCell) {
  // A single inside point: the closed surface around it is an octahedron-like fan; the mesh of
  // a tiny sphere around a grid point must be closed with Euler characteristic 2.
  GridSpec g = cubeGrid(1.0, 17);  // voxel 0.125, point 8 at the origin
  Checked c = meshAndCheck(sphereAt(0, 0, 0, 0.05), g);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.components, 1);
  EXPECT_GT(c.volume, 0);
}

TEST(Mesh, Sphere) {
  const double r = 0.8;
  GridSpec g = cubeGrid(1.0, 64);
  Expr s = sphereAt(0.03, 0.02, -0.01, r);
  Checked c = meshAndCheck(s, g);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.components, 1);
  EXPECT_NEAR(c.volume, 4.0 / 3.0 * kPi * r * r * r, 0.01 * 4.0 / 3.0 * kPi * r * r * r);
  EXPECT_NEAR(c.area, 4 * kPi * r * r, 0.01 * 4 * kPi * r * r);
  figures("sphere 64^3", c, 4.0 / 3.0 * kPi * r * r * r, 4 * kPi * r * r);
  checkVerticesOnSurface(s, c.mesh, g.voxel);
  checkNormals(c.mesh, [](const mc::Vec3& p) { return mc::Vec3{p[0] - 0.03, p[1] - 0.02, p[2] + 0.01}; });
}

TEST(Mesh, Block) {
  GridSpec g = cubeGrid(1.0, 64);
  Expr b = blockAt(0.01, -0.02, 0.015, 0.6, 0.5, 0.4);
  Checked c = meshAndCheck(b, g);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.components, 1);
  const double vol = 8 * 0.6 * 0.5 * 0.4, area = 8 * (0.6 * 0.5 + 0.6 * 0.4 + 0.5 * 0.4);
  // The raw mesher cuts edges and corners off (mesh_simplify.h puts them back): within 1% and 2%.
  EXPECT_NEAR(c.volume, vol, 0.01 * vol);
  EXPECT_NEAR(c.area, area, 0.02 * area);
  figures("block 64^3", c, vol, area);
  checkVerticesOnSurface(b, c.mesh, g.voxel);
}

// A field linear along every grid edge (a block's faces, a tilted slab): false position's first
// step from the two ends lands on the root, often exactly (f = 0). Such a root ends the edge's
// search: two end values, that step and at most one more, never the bisections that a zero
// end value used to trigger (12 evaluations an edge).
TEST(Mesh, RootsHitExactlyEndTheirEdgesSearch) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr slab = min(min(0.31 - abs(0.6 * x + 0.8 * z - 0.05), 0.7 - abs(0.8 * x - 0.6 * z)), 0.6 - abs(y));
  for (const Expr& m : {blockAt(0.013, -0.021, 0.007, 0.61, 0.43, 0.37), slab}) {
    TapePtr tape = Tape::compile(m, 3);
    Mesh mesh = meshGrid(tape, cubeGrid(1.0, 48), {}, 0);
    ASSERT_GT(mesh.positions.size(), 1000u);
    EXPECT_EQ(mc::checkEdgePairs(mesh.triangles, mesh.positions.size()), "");
    EXPECT_LT(double(mesh.stats.rootEvals), 4.5 * double(mesh.positions.size()));
  }
}

TEST(Mesh, GridAlignedBlockHasNoDegenerateTriangles) {
  // Faces exactly on grid planes: many values are exactly 0 and roots fall on grid points.
  GridSpec g = cubeGrid(1.0, 65);  // voxel 1/32: +-0.5 are grid planes
  Expr b = blockAt(0, 0, 0, 0.5, 0.5, 0.5);
  Checked c = meshAndCheck(b, g);  // watertight and min area checked inside
  EXPECT_EQ(c.euler, 2);
  EXPECT_NEAR(c.volume, 1.0, 0.01);
  // A sphere through grid points too (r = 0.5: (0.5, 0, 0) is on the surface).
  Checked s = meshAndCheck(sphereAt(0, 0, 0, 0.5), g);
  EXPECT_EQ(s.euler, 2);
  EXPECT_NEAR(s.volume, 4.0 / 3.0 * kPi * 0.125, 0.01 * 4.0 / 3.0 * kPi * 0.125);
}

TEST(Mesh, Torus) {
  const double R = 0.6, r = 0.25;
  GridSpec g = cubeGrid(1.0, 64);
  Expr t = torusZ(R, r);
  Checked c = meshAndCheck(t, g);
  EXPECT_EQ(c.euler, 0);  // genus 1
  EXPECT_EQ(c.components, 1);
  EXPECT_NEAR(c.volume, 2 * kPi * kPi * R * r * r, 0.01 * 2 * kPi * kPi * R * r * r);
  EXPECT_NEAR(c.area, 4 * kPi * kPi * R * r, 0.01 * 4 * kPi * kPi * R * r);
  figures("torus 64^3", c, 2 * kPi * kPi * R * r * r, 4 * kPi * kPi * R * r);
  checkVerticesOnSurface(t, c.mesh, g.voxel);
  checkNormals(c.mesh, [&](const mc::Vec3& p) {
    double q = std::sqrt(p[0] * p[0] + p[1] * p[1]);
    return mc::Vec3{p[0] - R * p[0] / q, p[1] - R * p[1] / q, p[2]};
  });
}

TEST(Mesh, BlockMinusSphere) {
  // The sphere is centred on a corner of the block: it removes one eighth of a ball.
  const double h = 0.6, r = 0.45;
  GridSpec g = cubeGrid(1.0, 64);
  Expr m = min(blockAt(0, 0, 0, h, h, h), -sphereAt(h, h, h, r));
  Checked c = meshAndCheck(m, g);
  EXPECT_EQ(c.euler, 2);
  const double vol = 8 * h * h * h - kPi * r * r * r / 6;
  const double area = 24 * h * h - 3 * kPi * r * r / 4 + kPi * r * r / 2;
  EXPECT_NEAR(c.volume, vol, 0.01 * vol);
  EXPECT_NEAR(c.area, area, 0.02 * area);
  figures("block minus sphere 64^3", c, vol, area);
  checkVerticesOnSurface(m, c.mesh, g.voxel);
}

TEST(Mesh, BlendedUnion) {
  Expr a = sphereAt(-0.35, 0, 0, 0.4), b = sphereAt(0.35, 0, 0, 0.4);
  Expr m = blendUnion(a, b, 0.1, 0.3, 0.3);
  GridSpec g = cubeGrid(1.0, 64);
  Checked c = meshAndCheck(m, g);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.components, 1);
  // More than the plain union of the two balls (the blend adds material); no closed form, so
  // the volume must agree with a finer mesh (96^3) within 1%.
  const double cap = kPi * 0.05 * 0.05 * (3 * 0.4 - 0.05) / 3;  // overlap lens half
  EXPECT_GT(c.volume, 2 * (4.0 / 3.0 * kPi * 0.064) - 2 * cap);
  Checked fine = meshAndCheck(m, cubeGrid(1.0, 96));
  EXPECT_NEAR(c.volume, fine.volume, 0.01 * fine.volume);
  EXPECT_NEAR(c.area, fine.area, 0.01 * fine.area);
  figures("blended union (96^3 as reference)", c, fine.volume, fine.area);
  checkVerticesOnSurface(m, c.mesh, g.voxel);
}

TEST(Mesh, TwistedBlockKeepsItsVolume) {
  // A twist about z preserves volume: the block's volume, 0.8 * 0.8 * 1.2.
  Expr b = twistRate(blockAt(0, 0, 0, 0.4, 0.4, 0.6), Axis::Z, 1.2);
  GridSpec g = cubeGrid(1.0, 64);
  Checked c = meshAndCheck(b, g);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.components, 1);
  EXPECT_NEAR(c.volume, 0.768, 0.01 * 0.768);
  figures("twisted block 64^3 (area: none)", c, 0.768, c.area);
  checkVerticesOnSurface(b, c.mesh, g.voxel);
}

TEST(Mesh, TwoBodies) {
  Expr m = max(sphereAt(-0.5, 0, 0, 0.35), blockAt(0.5, 0.1, 0, 0.3, 0.3, 0.3));
  GridSpec g = cubeGrid(1.0, 64);
  Checked c = meshAndCheck(m, g);
  EXPECT_EQ(c.components, 2);
  EXPECT_EQ(c.euler, 4);
  const double vol = 4.0 / 3.0 * kPi * 0.35 * 0.35 * 0.35 + 0.216;
  EXPECT_NEAR(c.volume, vol, 0.01 * vol);
  figures("two bodies 64^3 (area: none)", c, vol, c.area);
}

TEST(Mesh, SameMeshWhateverTheSplitAndOrder) {
  Expr m = max(torusZ(0.55, 0.22), min(blockAt(0.1, 0.1, 0.1, 0.5, 0.3, 0.4), -sphereAt(0.4, 0.3, 0.4, 0.3)));
  TapePtr tape = Tape::compile(m, 3);
  GridSpec g = cubeGrid(1.0, 61);  // 61 points: regions end off the multiples of 8
  Mesh whole = meshGrid(tape, g, {}, 0);
  ASSERT_GT(whole.triangles.size(), 1000u);
  EXPECT_EQ(mc::checkEdgePairs(whole.triangles, whole.positions.size()), "");
  for (int brick : {8, 16, 24, 40}) {
    SCOPED_TRACE("brick " + std::to_string(brick));
    expectIdentical(whole, meshGrid(tape, g, {}, brick));
  }
  // Uneven splits (3 x 2 x 1 regions of different sizes) merged in shuffled orders.
  std::vector<MeshPiece> pieces;
  const int xs[] = {0, 16, 40, 61}, ys[] = {0, 24, 61};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) pieces.push_back(meshRegion(tape, g, {xs[i], ys[j], 0}, {xs[i + 1], ys[j + 1], 61}));
  std::mt19937 rng(7);
  for (int round = 0; round < 3; ++round) {
    std::shuffle(pieces.begin(), pieces.end(), rng);
    expectIdentical(whole, mergePieces(pieces));
  }
  // Serial and threaded runs agree.
  MeshOptions serial;
  serial.threads = 1;
  expectIdentical(whole, meshGrid(tape, g, serial, 0));
}

TEST(Mesh, PiecesNeverRepeatATriangle) {
  TapePtr tape = Tape::compile(sphereAt(0, 0, 0, 0.7), 3);
  GridSpec g = cubeGrid(1.0, 48);
  size_t total = 0;
  for (int x = 0; x < 48; x += 16)
    for (int y = 0; y < 48; y += 16)
      for (int z = 0; z < 48; z += 16) total += meshRegion(tape, g, {x, y, z}, {x + 16, y + 16, z + 16}).triangles.size();
  EXPECT_EQ(total, meshGrid(tape, g).triangles.size());
}

TEST(Mesh, RejectsBadRegions) {
  TapePtr tape = Tape::compile(sphereAt(0, 0, 0, 0.7), 3);
  GridSpec g = cubeGrid(1.0, 32);
  EXPECT_THROW(meshRegion(tape, g, {4, 0, 0}, {16, 16, 16}), std::invalid_argument);
  EXPECT_THROW(meshGrid(tape, g, {}, 12), std::invalid_argument);
  MeshPiece empty = meshRegion(tape, g, {32, 0, 0}, {40, 8, 8});
  EXPECT_TRUE(empty.triangles.empty());
}

// Offset of a block by a ball of radius 0.2 (max over u in the ball of block(X - u)):
// evaluated by branch and bound, which the root finder runs lane by lane.
namespace {
Expr roundedBlock() {
  Expr body = remap(blockAt(0, 0, 0, 0.3, 0.3, 0.3), {Expr::x(0) - Expr::x(3), Expr::x(1) - Expr::x(4), Expr::x(2) - Expr::x(5)});
  ExtremumSpec spec;
  spec.body = body;
  spec.inputs = {X(), Y(), Z()};
  spec.hidden = 3;
  spec.domain = DomainKind::Ball;
  spec.radius = 0.2;
  spec.tolerance = 1e-3;
  return extremum(spec);
}
}  // namespace

TEST(Mesh, ExtremumModelIsSplitInvariant) {
  TapePtr tape = Tape::compile(roundedBlock(), 3);
  GridSpec g = cubeGrid(0.8, 15);
  Mesh whole = meshGrid(tape, g, {}, 0);
  ASSERT_GT(whole.triangles.size(), 100u);
  EXPECT_EQ(mc::checkEdgePairs(whole.triangles, whole.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(whole.triangles, whole.positions.size()), 2);
  expectIdentical(whole, meshGrid(tape, g, {}, 8));
  // Volume of the rounded block: cube + 6 slabs + 12 quarter cylinders + 8 ball eighths.
  const double a = 0.6, r = 0.2;
  const double vol = a * a * a + 6 * a * a * r + 3 * kPi * r * r * a + 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(mc::enclosedVolume(whole.positions, whole.triangles), vol, 0.03 * vol);
}

TEST(Mesh, ExtremumVerticesLieOnTheSurface) {
  // Same rounded block: the set is exactly {dist(X, cube of half side 0.3) <= 0.2}, so every
  // vertex's distance to the surface and every normal has an exact answer. Vertices from
  // grid-point values and warm-started searches along the edge (the default) against the
  // generic root finder with Danskin normals: both within the searches' precision of the
  // surface, normals from the tetrahedra's values close to the exact ones (Danskin's pick one
  // operand's gradient at the kink where the body reaches its maximum), far fewer searches.
  TapePtr tape = Tape::compile(roundedBlock(), 3);
  GridSpec g = cubeGrid(0.8, 20);
  MeshOptions generic;
  generic.extremumVertices = false;
  Mesh a = meshGrid(tape, g, {}, 0), b = meshGrid(tape, g, generic, 0);
  ASSERT_GT(a.positions.size(), 1000u);
  EXPECT_EQ(mc::checkEdgePairs(a.triangles, a.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(a.triangles, a.positions.size()), 2);
  EXPECT_EQ(mc::selfIntersections(a.positions, a.triangles), 0u);
  // Distance to the surface and the outward normal there, exactly.
  auto exact = [](const std::array<double, 3>& p, std::array<double, 3>& n) {
    std::array<double, 3> q;
    for (int c = 0; c < 3; ++c) q[c] = std::min(std::max(p[c], -0.3), 0.3);
    const double d = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    for (int c = 0; c < 3; ++c) n[c] = d > 0 ? (p[c] - q[c]) / d : 0.0;
    return std::fabs(d - 0.2);
  };
  auto measure = [&](const Mesh& m, double& worstDistance, double& meanAngle, double& worstAngle) {
    worstDistance = meanAngle = worstAngle = 0;
    for (size_t v = 0; v < m.positions.size(); ++v) {
      std::array<double, 3> n;
      worstDistance = std::max(worstDistance, exact(m.positions[v], n) / g.voxel);
      const double c = n[0] * m.normals[v][0] + n[1] * m.normals[v][1] + n[2] * m.normals[v][2];
      const double angle = std::acos(std::min(1.0, std::max(-1.0, c))) * 180 / kPi;
      meanAngle += angle / double(m.positions.size());
      worstAngle = std::max(worstAngle, angle);
    }
  };
  double da, ma, wa, db, mb, wb;
  measure(a, da, ma, wa);
  measure(b, db, mb, wb);
  std::printf("extremum vertices: %zu, searches %llu, distance <= %.4f voxel, normals mean %.2f max %.1f deg\n",
              a.positions.size(), (unsigned long long)a.stats.rootEvals, da, ma, wa);
  std::printf("generic root finder: %zu, searches %llu + %llu gradients, distance <= %.4f voxel, normals mean %.2f max %.1f deg\n",
              b.positions.size(), (unsigned long long)b.stats.rootEvals, (unsigned long long)b.stats.gradientEvals, db, mb, wb);
  EXPECT_LT(da, 0.05);  // the search's tolerance (1e-3) is 0.015 voxel here, the stop 1/256 edge
  EXPECT_LT(db, 0.05);
  EXPECT_LT(ma, 3.0);
  EXPECT_LT(wa, 45.0);
  EXPECT_EQ(a.stats.gradientEvals, 0u);
  EXPECT_LT(double(a.stats.rootEvals), 3.5 * double(a.positions.size()));
  EXPECT_LT(double(a.stats.rootEvals + a.stats.samplePointEvals),
            0.35 * double(b.stats.rootEvals + b.stats.samplePointEvals + 5 * b.stats.gradientEvals));
  const double vol = 0.216 + 6 * 0.36 * 0.2 + 3 * kPi * 0.04 * 0.6 + 4.0 / 3.0 * kPi * 0.008;
  EXPECT_NEAR(mc::enclosedVolume(a.positions, a.triangles), vol, 0.01 * vol);
}

TEST(Mesh, ExtremumModelsAreClosedAcrossLeafBoundaries) {
  // Issue 29: with the extremum path's band of 0, two 8^3 tiles of opposite signs could meet
  // with the surface between their last and first points; neither was a leaf, so the cells
  // between them were never visited and the mesh had holes on leaf boundaries. A 4D ball
  // projected to 3D (the unit ball, eq. 4.2) and a ball swept along a segment (a capsule), at
  // grids where the holes appeared: closed, one sphere each, volumes near the formulas.
  const Expr ball4 = 1.0 - square(X()) - square(Y()) - square(Z()) - square(Expr::x(3));
  const Expr projected = project(ball4, 4, {3}, Bounds{{-1.0}, {1.0}});
  const Expr ball = 0.5 - sqrt(square(X()) + square(Y()) + square(Z()));
  Motion line;
  line.translation = {-1.0 + 2.0 * X(), Expr::constant(0.0), Expr::constant(0.0)};
  const Expr capsule = sweep(ball, 3, line, 0.0, 1.0);
  struct Case {
    const char* name;
    Expr model;
    GridSpec grid;
    double volume;
  } cases[] = {{"projected 4D ball", projected, cubeGrid(1.2, 64), 4.0 / 3.0 * kPi},
               {"swept ball", capsule, cubeGrid(1.6, 72), kPi * 0.25 * 2.0 + 4.0 / 3.0 * kPi * 0.125}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Mesh m = meshGrid(Tape::compile(c.model, 3), c.grid, {}, 32);
    EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
    EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), 2);
    EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), c.volume, 0.005 * c.volume);
  }
}

TEST(Mesh, ExtremumNonConvexSumIsSplitInvariant) {
  // Issue 17's L-shaped slab (+) ball (frMinkowski's form: max over the ball's box of
  // min(A(X - u), B(u))), whose field is kinked at the surface: the same mesh for one region,
  // bricks of 8 and 16 and a serial run, closed, embedded, its volume near the exact prism
  // formula (bench_minkowski_peers.py).
  auto box = [](double x0, double y0, double z0, double x1, double y1, double z1) {
    return min(min(min(X() - x0, x1 - X()), min(Y() - y0, y1 - Y())), min(Z() - z0, z1 - Z()));
  };
  const Expr slab = min(box(-1, -1, -0.25, 1, 1, 0.25), -box(-0.2, -0.2, -1, 1.3, 1.3, 1));
  const Expr ball = 0.09 - square(X()) - square(Y()) - square(Z());
  TapePtr tape = Tape::compile(minkowskiSum(slab, ball, 3, Bounds{{-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}}), 3);
  GridSpec g = cubeGrid(1.5, 34);
  Mesh whole = meshGrid(tape, g, {}, 0);
  EXPECT_EQ(mc::checkEdgePairs(whole.triangles, whole.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(whole.triangles, whole.positions.size()), 2);
  EXPECT_EQ(mc::selfIntersections(whole.positions, whole.triangles), 0u);
  expectIdentical(whole, meshGrid(tape, g, {}, 8));
  expectIdentical(whole, meshGrid(tape, g, {}, 16));
  MeshOptions serial;
  serial.threads = 1;
  expectIdentical(whole, meshGrid(tape, g, serial, 0));
  const double A = 4 - 1.44, L = 8, c = 5 * kPi / 4 - 1, r = 0.3;
  const double vol = 0.5 * (A + L * r + c * r * r) + 2 * A * r + kPi * L * r * r / 2 + 4.0 / 3.0 * c * r * r * r;
  EXPECT_NEAR(mc::enclosedVolume(whole.positions, whole.triangles), vol, 0.005 * vol);
}

TEST(Mesh, SelfIntersectionCheckFindsCrossings) {
  // Two triangles crossing each other, one touching another at an interior point, a folded
  // pair sharing an edge, and a clean pair sharing a vertex.
  std::vector<mc::Vec3> p = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}, {3, 3, 0}};
  EXPECT_EQ(mc::selfIntersections(p, {{0, 1, 2}, {3, 4, 5}}), 1u);
  std::vector<mc::Vec3> touch = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 1}, {1.5, 1.5, 1}};
  EXPECT_EQ(mc::selfIntersections(touch, {{0, 1, 2}, {3, 4, 5}}), 1u);
  std::vector<mc::Vec3> fold = {{0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {1, 2, 0}};
  EXPECT_EQ(mc::selfIntersections(fold, {{0, 1, 2}, {1, 0, 3}}), 1u);
  std::vector<mc::Vec3> flat = {{0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {1, -1, 0}};
  EXPECT_EQ(mc::selfIntersections(flat, {{0, 1, 2}, {1, 0, 3}}), 0u);
  std::vector<mc::Vec3> corner = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0.5}, {0, -1, 0.5}};
  EXPECT_EQ(mc::selfIntersections(corner, {{0, 1, 2}, {0, 3, 4}}), 0u);
  std::vector<mc::Vec3> overlapCorner = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.2, 1, 0}};
  EXPECT_EQ(mc::selfIntersections(overlapCorner, {{0, 1, 2}, {0, 3, 4}}), 1u);
}

TEST(Mesh, SelfIntersectionCheckFindsAPulledVertex) {
  // A sphere's vertex pulled through the far side: its fan crosses the surface.
  TapePtr tape = Tape::compile(sphereAt(0, 0, 0, 0.7), 3);
  Mesh m = meshGrid(tape, cubeGrid(1.0, 24));
  ASSERT_EQ(mc::selfIntersections(m.positions, m.triangles), 0u);
  for (int c = 0; c < 3; ++c) m.positions[0][c] *= -1.3;
  EXPECT_GT(mc::selfIntersections(m.positions, m.triangles), 0u);
}

TEST(Mesh, SphereAndTorusAt128) {
  // The resolution: tighter tolerances (0.1%).
  GridSpec g = cubeGrid(1.0, 128);
  Checked s = meshAndCheck(sphereAt(0.03, 0.02, -0.01, 0.8), g);
  const double vs = 4.0 / 3.0 * kPi * 0.512, as = 4 * kPi * 0.64;
  EXPECT_EQ(s.euler, 2);
  EXPECT_NEAR(s.volume, vs, 0.001 * vs);
  EXPECT_NEAR(s.area, as, 0.001 * as);
  figures("sphere 128^3", s, vs, as);
  Checked t = meshAndCheck(torusZ(0.6, 0.25), g);
  const double vt = 2 * kPi * kPi * 0.6 * 0.0625, at = 4 * kPi * kPi * 0.6 * 0.25;
  EXPECT_EQ(t.euler, 0);
  EXPECT_NEAR(t.volume, vt, 0.001 * vt);
  EXPECT_NEAR(t.area, at, 0.001 * at);
  figures("torus 128^3", t, vt, at);
}

TEST(Mesh, RandomCsgModelsAreClosedEmbeddedAndSplitInvariant) {
  // Random unions, intersections and differences of balls, blocks and tori on grids with odd
  // sizes and offsets (surfaces through grid points included: dyadic radii and centres).
  std::mt19937 rng(20261126);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  auto dyadic = [&](double v) { return std::round(v * 16) / 16; };
  auto primitive = [&](int kind) -> Expr {
    double cx = u(rng), cy = u(rng), cz = u(rng);
    if (rng() % 2) cx = dyadic(cx), cy = dyadic(cy), cz = dyadic(cz);
    switch (kind % 3) {
      case 0: return sphereAt(cx, cy, cz, 0.2 + 0.3 * std::abs(u(rng)));
      case 1: return blockAt(cx, cy, cz, 0.15 + 0.3 * std::abs(u(rng)), 0.15 + 0.3 * std::abs(u(rng)), 0.15 + 0.3 * std::abs(u(rng)));
      default: return remap(torusZ(0.3, 0.1), {X() - cx, Z() - cy, Y() - cz});
    }
  };
  int meshed = 0;
  for (int round = 0; round < 24; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    Expr m = primitive(int(rng()));
    for (int k = 0; k < 3; ++k) {
      Expr p = primitive(int(rng()));
      unsigned op = rng() % 10;
      if (op < 5) m = max(m, p);        // union
      else if (op < 7) m = min(m, p);   // intersection
      else m = min(m, -p);              // difference
    }
    TapePtr tape = Tape::compile(m, 3);
    const int res = 25 + int(rng() % 20);
    GridSpec g = GridSpec::fromBounds({-1 - 0.01 * u(rng), -1, -1}, {1, 1 + 0.01 * u(rng), 1}, res);
    Mesh whole = meshGrid(tape, g);
    if (whole.triangles.empty()) continue;
    ++meshed;
    EXPECT_EQ(mc::checkEdgePairs(whole.triangles, whole.positions.size()), "");
    EXPECT_EQ(mc::selfIntersections(whole.positions, whole.triangles), 0u);
    EXPECT_GT(mc::enclosedVolume(whole.positions, whole.triangles), 0.0);
    EXPECT_EQ(mc::eulerCharacteristic(whole.triangles, whole.positions.size()) % 2, 0);
    expectIdentical(whole, meshGrid(tape, g, {}, 8 * int(1 + rng() % 3)));
    // Simplified (sharp features on): still closed, embedded, the same genus, the same for
    // any split, every vertex near the surface.
    SimplifyOptions so;
    so.tolerance = 0.1;
    Mesh featured = whole, other = meshGrid(tape, g, {}, 8 * int(1 + rng() % 3));
    simplifyMesh(featured, tape, g, so);
    simplifyMesh(other, tape, g, so);
    EXPECT_EQ(mc::checkEdgePairs(featured.triangles, featured.positions.size()), "");
    EXPECT_EQ(mc::selfIntersections(featured.positions, featured.triangles), 0u);
    EXPECT_EQ(mc::eulerCharacteristic(featured.triangles, featured.positions.size()),
              mc::eulerCharacteristic(whole.triangles, whole.positions.size()));
    expectIdentical(featured, other);
    checkVerticesNearSurface(m, featured, g.voxel);
  }
  EXPECT_GE(meshed, 15);
}
