// The simplifier (mesh_simplify.h): adaptive meshes that stay closed, oriented, embedded and
// within the stated error of the true surface; sharp edges and corners recovered; a block
// meshes to a few dozen triangles at any resolution.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>
#include <cstdio>

#include "core/mesh_checks.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/evaluators/float_error.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/primitives/ops.h"

using namespace frep;
namespace mc = mesh_checks;
using namespace mesh_models;

namespace {

struct Result {
  Mesh mesh;
  SimplifyStats stats;
  size_t rawTriangles = 0;
  double volume = 0, area = 0;
};

// Meshes, simplifies and checks what must hold for every model: closed and oriented, embedded
// (exact predicates), no degenerate triangle, the Euler characteristic unchanged, and every
// point of every triangle within the stated bound of the surface (dense sampling, measured by
// bisection along the triangle's normal against the model itself).
Result simplifyAndCheck(const Expr& model, const GridSpec& g, double tolVoxels, bool sharp = true, int brick = 0) {
  Result r;
  TapePtr tape = Tape::compile(model, 3);
  r.mesh = meshGrid(tape, g, {}, brick);
  const Mesh raw = r.mesh;
  r.rawTriangles = r.mesh.triangles.size();
  long euler0 = mc::eulerCharacteristic(r.mesh.triangles, r.mesh.positions.size());
  SimplifyOptions so;
  so.tolerance = tolVoxels;
  so.sharpFeatures = sharp;
  r.stats = simplifyMesh(r.mesh, tape, g, so);
  const Mesh& m = r.mesh;
  EXPECT_EQ(m.positions.size(), m.normals.size());
  EXPECT_EQ(m.positions.size(), m.keys.size());
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), euler0);
  EXPECT_EQ(mc::selfIntersections(m.positions, m.triangles), 0u);
  r.volume = mc::enclosedVolume(m.positions, m.triangles);
  r.area = mc::surfaceArea(m.positions, m.triangles);
  // No degenerate triangle: quality (4 sqrt3 area / sum of squared edges) bounded below.
  double worstQuality = 1;
  for (const auto& t : m.triangles) {
    auto a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    double s = mc::dot(mc::sub(b, a), mc::sub(b, a)) + mc::dot(mc::sub(c, b), mc::sub(c, b)) +
               mc::dot(mc::sub(a, c), mc::sub(a, c));
    worstQuality = std::min(worstQuality, 2 * std::sqrt(3.0) * mc::norm(mc::cross(mc::sub(b, a), mc::sub(c, a))) / s);
  }
  EXPECT_GT(worstQuality, 1e-4);
  // Every point of every triangle (10x10 per triangle, denser than the simplifier's own checks
  // for small triangles) is within the reported bound of the surface: certified by an inside and an
  // outside point within that distance (the point itself, or along +-normal or one of 26 grid
  // directions at that distance or 1/2, 1/4, 1/8 of it), as the segment between them crosses the
  // surface inside the ball.
  PointEvaluator pe;
  std::set<std::array<mc::Vec3, 3>> untouched;  // the mesher's triangles, by corner positions
  for (const auto& t : raw.triangles) untouched.insert({raw.positions[t[0]], raw.positions[t[1]], raw.positions[t[2]]});
  size_t far = 0;
  for (const auto& t : m.triangles) {
    auto a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    // A triangle left as the mesher made it may chord across a crease of the model (up to a
    // voxel); one made by the simplifier is within its reported bound.
    const double bound = untouched.count({a, b, c}) ? g.voxel : 1.001 * r.stats.errorBound + 1e-9;
    auto n = mc::cross(mc::sub(b, a), mc::sub(c, a));
    double ln = mc::norm(n);
    for (int i = 0; i < 10; ++i)
      for (int j = 0; i + j < 10; ++j) {
        double u = (i + 1.0 / 3) / 10, v = (j + 1.0 / 3) / 10;
        std::array<double, 3> p;
        for (int k = 0; k < 3; ++k) p[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
        bool in = false, out = false;
        double radius = bound;
        auto probe = [&](double dx, double dy, double dz) {
          double len = std::sqrt(dx * dx + dy * dy + dz * dz);
          std::array<double, 3> q{p[0] + radius * dx / len, p[1] + radius * dy / len, p[2] + radius * dz / len};
          (pe.eval(*tape, q.data()) >= 0 ? in : out) = true;
        };
        (pe.eval(*tape, p.data()) >= 0 ? in : out) = true;
        // Shorter radii too (any two points in the ball will do): in a gap or a wall thinner than
        // the bound every probe at the full radius may land on the same side.
        for (int halvings = 0; halvings < 4 && !(in && out); ++halvings, radius *= 0.5) {
          probe(n[0] / ln, n[1] / ln, n[2] / ln);
          probe(-n[0] / ln, -n[1] / ln, -n[2] / ln);
          for (int d = 0; d < 27 && !(in && out); ++d)
            if (d != 13) probe(d / 9 - 1, (d / 3) % 3 - 1, d % 3 - 1);
        }
        far += !(in && out);
        if (!(in && out) && getenv("FREP_DUMP") && far < 6) {
          double fa = pe.eval(*tape, a.data()), fb = pe.eval(*tape, b.data()), fc = pe.eval(*tape, c.data()), fp = pe.eval(*tape, p.data());
          std::printf("   far: tri (%g %g %g) (%g %g %g) (%g %g %g) f %g %g %g  p %g,%g f(p) %g\n", a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], fa, fb, fc, u, v, fp);
        }
      }
  }
  EXPECT_EQ(far, 0u);
  // Every vertex within half a voxel of the surface (an inside and an outside point within 0.49
  // voxel of it), and every vertex normal outward: on the side of its fan's area-weighted normal.
  std::vector<mc::Vec3> fan(m.positions.size(), mc::Vec3{0, 0, 0});
  for (const auto& t : m.triangles) {
    auto n = mc::cross(mc::sub(m.positions[t[1]], m.positions[t[0]]), mc::sub(m.positions[t[2]], m.positions[t[0]]));
    for (uint32_t v : t)
      for (int k = 0; k < 3; ++k) fan[v][k] += n[k];
  }
  size_t inward = 0;
  for (size_t i = 0; i < m.positions.size(); ++i) inward += mc::dot(m.normals[i], fan[i]) <= 0;
  EXPECT_EQ(inward, 0u);
  EXPECT_EQ(mc::verticesFarFromSurface(m.positions, m.normals, 0.49 * g.voxel,
                                       [&](const mc::Vec3& p) { return pe.eval(*tape, p.data()); }),
            0u);
  return r;
}

void figures(const char* name, const Result& r, double volume, double area) {
  std::printf("[figures] %-28s %8zu -> %7zu triangles  volume err %+.3f%%  area err %+.3f%%  bound %.3g  "
              "collapses %llu  evals %llu  rejected topo %llu shape %llu error %llu isect %llu\n",
              name, r.rawTriangles, r.mesh.triangles.size(), 100 * (r.volume / volume - 1), 100 * (r.area / area - 1),
              r.stats.errorBound, (unsigned long long)r.stats.collapses, (unsigned long long)r.stats.modelEvals,
              (unsigned long long)r.stats.rejectedTopology, (unsigned long long)r.stats.rejectedShape,
              (unsigned long long)r.stats.rejectedError, (unsigned long long)r.stats.rejectedIntersection);
}

}  // namespace

TEST(MeshSimplify, BlockIsAFewDozenTrianglesAtAnyResolution) {
  const double a = 0.9, b = 0.7, c = 0.5, cx = 0.013, cy = -0.021, cz = 0.007;  // not grid-aligned
  for (int res : {32, 64, 128}) {
    Result r = simplifyAndCheck(blockAt(cx, cy, cz, a, b, c), cubeGrid(1.2, res), 0.1);
    double V = 8 * a * b * c, A = 8 * (a * b + b * c + c * a);
    figures(("block " + std::to_string(res)).c_str(), r, V, A);
    EXPECT_LE(r.mesh.triangles.size(), 48u) << res;
    EXPECT_NEAR(r.volume, V, 1e-3 * V);
    EXPECT_NEAR(r.area, A, 5e-3 * A);
    // The corners are vertices (the quadric of three faces' tangent planes has one minimum).
    int exact = 0;
    for (int k = 0; k < 8; ++k) {
      mc::Vec3 corner{cx + (k & 1 ? a : -a), cy + (k & 2 ? b : -b), cz + (k & 4 ? c : -c)};
      double best = INFINITY;
      for (const auto& p : r.mesh.positions) best = std::min(best, mc::norm(mc::sub(p, corner)));
      exact += best < 1e-9;
      EXPECT_LT(best, cubeGrid(1.2, res).voxel) << res << " corner " << k;
    }
    EXPECT_GE(exact, 6) << res;
    std::printf("[figures]   %d of 8 corners exact\n", exact);
  }
}

// Volume and area against formulas at 128^3. Every point of the mesh is within the error bound
// e of the surface, so the volume differs by at most about e times the area (plus the mesher's
// own error, 0.1%).
struct Case {
  const char* name;
  Expr model;
  double volume, area;  // area <= 0: no closed form
  long euler;
  bool fewTriangles;  // planar faces only
};

TEST(MeshSimplify, ModelsAt128AreClosedEmbeddedAndWithinTheBound) {
  const double h = 0.6, r = 0.45;
  std::vector<Case> cases = {
      {"sphere", sphereAt(0.03, 0.02, -0.01, 0.8), 4.0 / 3.0 * kPi * 0.512, 4 * kPi * 0.64, 2, false},
      {"torus", torusZ(0.6, 0.25), 2 * kPi * kPi * 0.6 * 0.0625, 4 * kPi * kPi * 0.6 * 0.25, 0, false},
      {"block minus sphere", min(blockAt(0, 0, 0, h, h, h), -sphereAt(h, h, h, r)),
       8 * h * h * h - kPi * r * r * r / 6, 24 * h * h - 3 * kPi * r * r / 4 + kPi * r * r / 2, 2, false},
      {"twisted block", twistRate(blockAt(0, 0, 0, 0.4, 0.4, 0.6), Axis::Z, 1.2), 0.768, 0, 2, false},
      {"two bodies", max(sphereAt(-0.5, 0, 0, 0.35), blockAt(0.5, 0.1, 0, 0.3, 0.3, 0.3)),
       4.0 / 3.0 * kPi * 0.35 * 0.35 * 0.35 + 0.216, 0, 4, false},
      {"block with a slot", min(blockAt(0.01, 0.02, 0.03, 0.8, 0.6, 0.4), -blockAt(0.01, 0.02, 0.43, 0.2, 0.7, 0.2)),
       8 * 0.8 * 0.6 * 0.4 - 0.4 * 1.2 * 0.2, 8 * (0.8 * 0.6 + 0.6 * 0.4 + 0.4 * 0.8) + 2 * 1.2 * 0.2 - 2 * 0.4 * 0.2, 2,
       true},
  };
  for (const Case& c : cases) {
    GridSpec g = cubeGrid(1.0, 128);
    Result r = simplifyAndCheck(c.model, g, 0.1);
    figures((std::string(c.name) + " 128").c_str(), r, c.volume, c.area > 0 ? c.area : r.area);
    if (getenv("FREP_DUMP")) {
      std::map<std::string, int> byNormal;
      for (auto& t : r.mesh.triangles) {
        auto n = mc::cross(mc::sub(r.mesh.positions[t[1]], r.mesh.positions[t[0]]), mc::sub(r.mesh.positions[t[2]], r.mesh.positions[t[0]]));
        double l = mc::norm(n);
        char buf[64];
        std::snprintf(buf, sizeof buf, "%+.1f %+.1f %+.1f", n[0] / l, n[1] / l, n[2] / l);
        byNormal[buf]++;
      }
      for (auto& [k, v] : byNormal) if (v > 100) std::printf("   %s : %d\n", k.c_str(), v);
    }
    EXPECT_EQ(mc::eulerCharacteristic(r.mesh.triangles, r.mesh.positions.size()), c.euler) << c.name;
    EXPECT_LE(r.stats.errorBound, g.voxel) << c.name;
    EXPECT_LT(r.mesh.triangles.size(), r.rawTriangles / 4) << c.name;
    const double area = c.area > 0 ? c.area : r.area;
    EXPECT_NEAR(r.volume, c.volume, r.stats.errorBound * area + 1e-3 * c.volume) << c.name;
    if (c.area > 0) {
      EXPECT_NEAR(r.area, c.area, 2e-3 * c.area) << c.name;
    }
    if (c.fewTriangles) {
      EXPECT_LE(r.mesh.triangles.size(), 600u) << c.name;
    }
  }
}

TEST(MeshSimplify, BlendedUnionKeepsItsVolume) {
  // No closed form: against the unsimplified mesh (within 0.1% of the finer meshes' volume).
  Expr m = blendUnion(sphereAt(-0.35, 0, 0, 0.4), sphereAt(0.35, 0, 0, 0.4), 0.1, 0.3, 0.3);
  GridSpec g = cubeGrid(1.0, 128);
  TapePtr tape = Tape::compile(m, 3);
  Mesh raw = meshGrid(tape, g);
  const double v0 = mc::enclosedVolume(raw.positions, raw.triangles), a0 = mc::surfaceArea(raw.positions, raw.triangles);
  Result r = simplifyAndCheck(m, g, 0.1);
  figures("blended union 128 (vs raw)", r, v0, a0);
  EXPECT_EQ(mc::eulerCharacteristic(r.mesh.triangles, r.mesh.positions.size()), 2);
  EXPECT_LT(r.mesh.triangles.size(), r.rawTriangles / 10);
  EXPECT_NEAR(r.volume, v0, r.stats.errorBound * a0);
}

namespace {

// A torus and a block with a ball taken out (creases, corners, curved faces): the split tests'
// model.
Expr torusAndNotchedBlock() {
  return max(torusZ(0.55, 0.22), min(blockAt(0.1, 0.1, 0.1, 0.5, 0.3, 0.4), -sphereAt(0.4, 0.3, 0.4, 0.3)));
}

void expectSameMesh(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.keys, b.keys);
}

}  // namespace

TEST(MeshSimplify, SameResultWhateverTheSplit) {
  Expr m = torusAndNotchedBlock();
  GridSpec g = cubeGrid(1.0, 61);
  TapePtr tape = Tape::compile(m, 3);
  SimplifyOptions so;
  so.tolerance = 0.1;
  Mesh a = meshGrid(tape, g, {}, 0), b = meshGrid(tape, g, {}, 16);
  const size_t raw = a.triangles.size();
  const SimplifyStats sa = simplifyMesh(a, tape, g, so), sb = simplifyMesh(b, tape, g, so);
  // Something was simplified (equal meshes would prove nothing otherwise), the same work both ways.
  EXPECT_EQ(sa.trianglesBefore, raw);
  EXPECT_EQ(sa.trianglesAfter, a.triangles.size());
  EXPECT_GT(sa.collapses, 1000u);
  EXPECT_LT(a.triangles.size() * 2, raw) << "simplified from " << raw << " to " << a.triangles.size() << " triangles";
  EXPECT_EQ(sa.collapses, sb.collapses);
  expectSameMesh(a, b);
}

// The farm's bricks of `brick` cells: each meshed and its own blocks simplified (meshRegion,
// simplifyRegion, as a worker does), then merged (not finished).
namespace {
Mesh bricksMeshedAndSimplified(const TapePtr& tape, const GridSpec& g, const SimplifyOptions& so, int brick) {
  std::vector<MeshPiece> pieces;
  const int32_t cells = int32_t(g.dims[0] - 1);
  for (int32_t x = 0; x < cells; x += brick)
    for (int32_t y = 0; y < cells; y += brick)
      for (int32_t z = 0; z < cells; z += brick) {
        std::array<int32_t, 3> lo{x, y, z}, hi{std::min(cells, x + brick), std::min(cells, y + brick), std::min(cells, z + brick)};
        pieces.push_back(meshRegion(tape, g, lo, hi));
        simplifyRegion(pieces.back(), tape, g, so, lo, hi);
      }
  return mergePieces(pieces);
}
}  // namespace

// The farm's way: each brick's piece simplified on its own (simplifyRegion, in the workers), then
// merged and finished: the same mesh as simplifying the whole, for bricks that are multiples of
// the 32-voxel blocks or not.
TEST(MeshSimplify, BricksSimplifyingTheirOwnBlocksGiveTheSameMesh) {
  Expr m = torusAndNotchedBlock();
  GridSpec g = cubeGrid(1.0, 100);
  TapePtr tape = Tape::compile(m, 3);
  SimplifyOptions so;
  so.tolerance = 0.1;
  Mesh whole = meshGrid(tape, g);
  SimplifyStats ws = simplifyMesh(whole, tape, g, so);
  for (int brick : {32, 64, 72, 96}) {  // 72: some blocks straddle bricks
    SCOPED_TRACE(brick);
    Mesh merged = bricksMeshedAndSimplified(tape, g, so, brick);
    EXPECT_GT(merged.carry.counters.collapses, 1000u);  // the bricks did a real share
    SimplifyOptions finish = so;
    finish.bricksSimplified = brick;
    SimplifyStats fs = simplifyMesh(merged, tape, g, finish);
    expectSameMesh(merged, whole);
    EXPECT_EQ(fs.trianglesBefore, ws.trianglesBefore);
    EXPECT_EQ(fs.collapses, ws.collapses);
    EXPECT_EQ(fs.modelEvals, ws.modelEvals);
    EXPECT_EQ(fs.errorBound, ws.errorBound);
  }
}

TEST(MeshSimplify, SameResultForAnyThreadCount) {
  // 100 points: 3 x 3 x 3 first-pass blocks of 32 voxels, run by 1 and by 2 threads.
  Expr m = torusAndNotchedBlock();
  GridSpec g = cubeGrid(1.0, 100);
  TapePtr tape = Tape::compile(m, 3);
  Mesh a = meshGrid(tape, g), b = a;
  SimplifyOptions one, two;
  one.tolerance = two.tolerance = 0.1;
  one.threads = 1;
  two.threads = 2;
  SimplifyStats sa = simplifyMesh(a, tape, g, one), sb = simplifyMesh(b, tape, g, two);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(sa.collapses, sb.collapses);
  EXPECT_EQ(sa.modelEvals, sb.modelEvals);
}

namespace {
// R-function blocks joined by a blended union (the division of hfBlendUni), as
// examples/chair.hf is built.
Expr chairLike() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  auto block = [&](double cx, double cy, double cz, double hx, double hy, double hz) {
    return rIntersection(rIntersection(hx - abs(x - cx), hy - abs(y - cy)), hz - abs(z - cz));
  };
  const Expr seat = block(0.0, 0.0, 0.1, 0.6, 0.6, 0.08), leg = block(0.3, 0.3, -0.3, 0.08, 0.08, 0.35);
  return rUnion(seat, leg) + 0.02 / (1.0 + square(seat / 0.1) + square(leg / 0.1));
}

// The model's mesh at res^3 simplified within 0.1 voxel with `on` and with `off` (their
// tolerances set here): the same mesh expected; both runs' stats.
std::pair<SimplifyStats, SimplifyStats> simplifiedBothWays(const TapePtr& tape, int res, SimplifyOptions on,
                                                           SimplifyOptions off) {
  GridSpec g = cubeGrid(1.0, res);
  Mesh a = meshGrid(tape, g), b = a;
  on.tolerance = off.tolerance = 0.1;
  const SimplifyStats sa = simplifyMesh(a, tape, g, on), sb = simplifyMesh(b, tape, g, off);
  expectSameMesh(a, b);
  return {sa, sb};
}
}  // namespace

// The error check's signs in float with the certified double fallback give the double path's
// mesh: the chair-like blocks and the split tests' model (min, max, square roots).
TEST(MeshSimplify, FloatSignsGiveTheDoubleMesh) {
  for (const Expr& m : {chairLike(), torusAndNotchedBlock()}) {
    TapePtr tape = Tape::compile(m, 3);
    ASSERT_TRUE(FloatErrorBound::supports(*tape));
    SimplifyOptions dbl;
    dbl.floatSigns = false;
    const auto [sa, sb] = simplifiedBothWays(tape, 80, {}, dbl);
    EXPECT_GT(sa.collapses, 1000u);
    EXPECT_EQ(sa.collapses, sb.collapses);
    EXPECT_EQ(sa.modelEvals, sb.modelEvals);
    EXPECT_EQ(sa.errorBound, sb.errorBound);
  }
}

// Levels decided by interval bounds (the triangle's two offset boxes) give the mesh of every
// sample evaluated: flat faces of axis-aligned R-function blocks (thin boxes, decided) joined by
// a blend (curved, not decided), a sphere, a block rotated off the axes (whose faces' boxes are
// thick: mostly not decided) and the notched block.
TEST(MeshSimplify, IntervalDecidedLevelsGiveTheSampledMesh) {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const double c = std::cos(0.4), s = std::sin(0.4);
  const Expr tilted = rIntersection(rIntersection(0.5 - abs(c * x + s * y), 0.4 - abs(c * y - s * x)), 0.3 - abs(z));
  int decidedSomewhere = 0;
  for (const Expr& m : {chairLike(), sphereAt(0.01, -0.02, 0.03, 0.7), tilted, torusAndNotchedBlock()}) {
    SimplifyOptions off;
    off.intervalLevels = false;
    const auto [sa, sb] = simplifiedBothWays(Tape::compile(m, 3), 96, {}, off);
    EXPECT_GT(sa.collapses, 500u);
    EXPECT_EQ(sa.collapses, sb.collapses);
    EXPECT_EQ(sa.errorBound, sb.errorBound);
    EXPECT_LE(sa.modelEvals, sb.modelEvals);
    decidedSomewhere += sa.modelEvals < sb.modelEvals;
  }
  EXPECT_GE(decidedSomewhere, 2);  // the path ran (the chair-like blocks, the notched block)
}

TEST(MeshSimplify, WithoutSharpFeaturesEveryVertexStaysAMesherVertex) {
  Expr m = blockAt(0.013, -0.021, 0.007, 0.9, 0.7, 0.5);
  GridSpec g = cubeGrid(1.2, 48);
  TapePtr tape = Tape::compile(m, 3);
  Mesh raw = meshGrid(tape, g);
  Result r = simplifyAndCheck(m, g, 0.1, false);
  figures("block 48 (no sharp)", r, 8 * 0.9 * 0.7 * 0.5, 8 * (0.63 + 0.35 + 0.45));
  for (size_t v = 0; v < r.mesh.positions.size(); ++v) {
    auto it = std::lower_bound(raw.keys.begin(), raw.keys.end(), r.mesh.keys[v]);
    ASSERT_TRUE(it != raw.keys.end() && *it == r.mesh.keys[v]);
    EXPECT_EQ(r.mesh.positions[v], raw.positions[it - raw.keys.begin()]);
  }
  EXPECT_LT(r.mesh.triangles.size(), r.rawTriangles / 4);  // flat faces still coarsen
}

TEST(MeshSimplify, ZeroToleranceLeavesTheMeshAlone) {
  GridSpec g = cubeGrid(1.2, 24);
  TapePtr tape = Tape::compile(sphereAt(0, 0, 0, 1), 3);
  Mesh a = meshGrid(tape, g), b = a;
  SimplifyStats st = simplifyMesh(b, tape, g, {});
  EXPECT_EQ(st.collapses, 0u);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.positions, b.positions);
}

TEST(MeshSimplify, SphereKeepsItsShapeWithinTheTolerance) {
  Result r = simplifyAndCheck(sphereAt(0, 0, 0, 1), cubeGrid(1.2, 64), 0.1);
  figures("sphere 64", r, 4 * kPi / 3, 4 * kPi);
  EXPECT_LT(r.mesh.triangles.size(), r.rawTriangles);
  EXPECT_NEAR(r.volume, 4 * kPi / 3, 5e-3 * 4 * kPi / 3);
}

// A cone cut by the grid's box ends in an open rim on the box's bottom face. The rim must stay
// exactly the mesher's: no rim vertex may leave the face (a collapse that moved one cut notches
// into the rim, up to many voxels deep at larger tolerances).
TEST(MeshSimplify, OpenRimOnTheBoxStaysOnTheBox) {
  const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  const Expr cone = 0.5 * (1.0 - Z) - sqrt(square(X) + square(Y));
  const GridSpec g = GridSpec::fromBounds({-1, -1, -0.5}, {1, 1, 1.2}, 96);
  TapePtr tape = Tape::compile(cone, 3);
  Mesh m = meshGrid(tape, g, {}, 0);
  auto rim = [](const Mesh& mesh) {
    std::set<std::pair<uint32_t, uint32_t>> directed;
    for (const auto& t : mesh.triangles)
      for (int c = 0; c < 3; ++c) directed.insert({t[c], t[(c + 1) % 3]});
    std::set<std::array<double, 3>> points;
    for (const auto& [a, b] : directed)
      if (!directed.count({b, a})) points.insert(mesh.positions[a]), points.insert(mesh.positions[b]);
    return points;
  };
  const auto rawRim = rim(m);
  ASSERT_GT(rawRim.size(), 100u);
  for (double tol : {0.1, 1.0}) {
    Mesh s = m;
    SimplifyOptions so;
    so.tolerance = tol;
    simplifyMesh(s, tape, g, so);
    EXPECT_LT(s.triangles.size(), m.triangles.size() / 10);
    const auto simplifiedRim = rim(s);
    EXPECT_EQ(simplifiedRim, rawRim) << "tolerance " << tol;
    for (const auto& p : simplifiedRim) EXPECT_EQ(p[2], g.origin[2]);
  }
}

// The error check samples only the upright sub-triangles' centroids of its m x m subdivision
// (errorSampleCells). Brute force over random triangles: no point of the triangle (its corners,
// points along its edges, random interior points) is farther from the nearest sample than from
// the nearest centroid of ALL m^2 sub-triangles, the set it replaced; every sample lies strictly
// inside, each once, m(m+1)/2 of them, and the first probe is the sub-triangle at the centroid.
TEST(MeshSimplify, ErrorSamplesCoverTheTriangleAsTheFullSubdivisionDoes) {
  uint64_t seed = 0x9e3779b97f4a7c15ull;
  auto uniform = [&] {  // splitmix64: deterministic on every platform
    uint64_t z = (seed += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return double((z ^ (z >> 31)) >> 11) * 0x1p-53;
  };
  using P2 = std::array<double, 2>;
  for (int m : {1, 2, 3, 4, 5, 7, 10, 16}) {
    const std::vector<std::array<int32_t, 2>>& cells = errorSampleCells(m);
    ASSERT_EQ(cells.size(), size_t(m) * (m + 1) / 2) << "m " << m;
    std::set<std::array<int32_t, 2>> distinct(cells.begin(), cells.end());
    EXPECT_EQ(distinct.size(), cells.size());
    for (const auto& c : cells) EXPECT_TRUE(c[0] >= 0 && c[1] >= 0 && c[0] + c[1] < m);
    EXPECT_EQ(cells[0], (std::array<int32_t, 2>{std::min(m / 3, m - 1), std::min(m / 3, m - 1 - std::min(m / 3, m - 1))}));
    for (int trial = 0; trial < 40; ++trial) {
      P2 a{uniform(), uniform()}, b{uniform(), uniform()}, c{uniform(), uniform()};
      if (trial % 4 == 0) c = {a[0] + 0.02 * uniform(), b[1] + 0.5};  // thin and obtuse ones too
      const P2 u{(b[0] - a[0]) / m, (b[1] - a[1]) / m}, v{(c[0] - a[0]) / m, (c[1] - a[1]) / m};
      auto at = [&](double s, double t) { return P2{a[0] + s * u[0] + t * v[0], a[1] + s * u[1] + t * v[1]}; };
      std::vector<P2> used, all;
      for (const auto& cell : cells) used.push_back(at(cell[0] + 1.0 / 3, cell[1] + 1.0 / 3));
      for (int i = 0; i < m; ++i)
        for (int j = 0; i + j < m; ++j) {
          all.push_back(at(i + 1.0 / 3, j + 1.0 / 3));
          if (i + j <= m - 2) all.push_back(at(i + 2.0 / 3, j + 2.0 / 3));
        }
      std::vector<P2> probe;  // in subdivision coordinates (s, t), s, t >= 0, s + t <= m
      for (int k = 0; k <= 64; ++k) {
        const double f = m * k / 64.0;
        probe.push_back({f, 0}), probe.push_back({0, f}), probe.push_back({m - f, f});
      }
      for (int k = 0; k < 400; ++k) {
        double s = uniform(), t = uniform();
        if (s + t > 1) s = 1 - s, t = 1 - t;
        probe.push_back({m * s, m * t});
      }
      auto nearest = [](const P2& p, const std::vector<P2>& set) {
        double best = INFINITY;
        for (const P2& q : set) best = std::min(best, std::hypot(p[0] - q[0], p[1] - q[1]));
        return best;
      };
      double coverUsed = 0, coverAll = 0;
      for (const P2& st : probe) {
        const P2 p = at(st[0], st[1]);
        coverUsed = std::max(coverUsed, nearest(p, used));
        coverAll = std::max(coverAll, nearest(p, all));
      }
      EXPECT_LE(coverUsed, coverAll * (1 + 1e-12)) << "m " << m << " trial " << trial;
    }
  }
}

// A ridge under a thin bent plate, closer than the tolerance. No other model here makes the
// self-intersection check reject a collapse: the error check alone keeps two surfaces apart when
// both stay within the tolerance of the model. Here the plate's underside has a concave crease
// right above the ridge, midway between grid columns, so the mesher's chord across it lies
// below the true crease (at z = gap instead of 0.3v + gap), and below the true ridge (0.3v).
// With sharp features a collapse of two of the ridge's flank vertices goes to the true ridge
// line, which passes the error check (the plate is a true surface there) but crosses that
// chord: only the self-intersection check stops it. At tolerance 1 the rejected collapses are
// on the plate's top, against its own underside. Without the check both results have improper
// triangle pairs (180 and 42).
// Creases along y at x = v/2. Ridge top at z = 0.3v, flanks at 45 degrees; the plate's
// underside at 0.3v + gap * v on the crease, sloping down at 0.6 to both sides, its top
// plateThickness * v above (vertically). At every grid column the point z = 0 is outside both,
// so the mesher keeps them apart.
namespace {
Expr ridgeUnderBentPlate(double v, double plateThickness, double gap) {
  const double top = 0.3 * v;
  const Expr u = X() - 0.5 * v;
  const Expr ridge = min(blockAt(0.013, 0.007, -0.2, 0.4, 0.35, 0.2 + top), top - Z() - abs(u));
  const Expr underside = Z() - (top + gap * v) + 0.6 * abs(u);
  const Expr plate = min(blockAt(-0.011, 0.003, 0.0, 0.37, 0.32, 0.4), min(underside, plateThickness * v - underside));
  return max(ridge, plate);
}
}  // namespace

TEST(MeshSimplify, RidgeUnderABentPlateNeedsTheIntersectionCheck) {
  const GridSpec g = cubeGrid(1.0, 49);  // x = 0 and z = 0 are grid planes
  uint64_t rejected = 0;
  for (const auto& [plateThickness, gap, tol] : {std::array<double, 3>{1.5, 0.05, 2.5}, {1.5, 0.1, 1.0}}) {
    SCOPED_TRACE(tol);
    // closed, embedded, within the bound
    Result r = simplifyAndCheck(ridgeUnderBentPlate(g.voxel, plateThickness, gap), g, tol);
    figures(("ridge under a bent plate, tol " + std::to_string(tol)).c_str(), r, r.volume, r.area);
    rejected += r.stats.rejectedIntersection;
  }
  EXPECT_GT(rejected, 0u);  // 21 + 3 when written
}

// The self-intersection check runs once per block; a block whose result fails it is simplified
// again with the check at every collapse. That rerun is a function of the block's input too:
// the ridge (whose blocks rerun) gives the same mesh simplified whole or brick by brick.
TEST(MeshSimplify, BlocksSimplifiedAgainGiveTheSameMeshWhateverTheSplit) {
  const GridSpec g = cubeGrid(1.0, 49);
  const TapePtr tape = Tape::compile(ridgeUnderBentPlate(g.voxel, 1.5, 0.05), 3);
  SimplifyOptions so;
  so.tolerance = 2.5;
  Mesh whole = meshGrid(tape, g);
  const SimplifyStats ws = simplifyMesh(whole, tape, g, so);
  ASSERT_GT(ws.rejectedIntersection, 0u);  // a block was simplified again
  for (int brick : {16, 24, 40}) {
    SCOPED_TRACE(brick);
    Mesh merged = bricksMeshedAndSimplified(tape, g, so, brick);
    SimplifyOptions finish = so;
    finish.bricksSimplified = brick;
    const SimplifyStats fs = simplifyMesh(merged, tape, g, finish);
    expectSameMesh(merged, whole);
    EXPECT_EQ(fs.collapses, ws.collapses);
    EXPECT_EQ(fs.rejectedIntersection, ws.rejectedIntersection);
    EXPECT_EQ(fs.errorBound, ws.errorBound);
  }
}

// The cell contractions (the connected vertices of a 1-, 2- or 4-voxel cell merged into one
// before the edge collapses) must keep sheets that share a cell apart: a spherical shell and a
// gap between two blocks, both narrower than two voxels, so that cells of 2 and 4 voxels hold
// vertices of both sides. Each side is its own connected piece of the cell and contracts on its
// own (or not at all); the result keeps two closed surfaces (Euler characteristic 4), embedded,
// within the bound, and far fewer triangles than the mesher's.
TEST(MeshSimplify, ThinWallsAndGapsStayApartWhenCellsAreContracted) {
  const GridSpec g = cubeGrid(1.0, 64);
  const double v = g.voxel;
  const Expr shell = 0.9 * v - abs(sqrt(square(X() - 0.01) + square(Y() + 0.02) + square(Z())) - 0.7);
  const Expr gap = max(blockAt(-0.4 - 0.75 * v, 0.01, 0.02, 0.4, 0.5, 0.45), blockAt(0.4 + 0.75 * v, 0.01, 0.02, 0.4, 0.5, 0.45));
  const double t = 1.8 * v, shellVolume = 4.0 / 3.0 * kPi * (std::pow(0.7 + t / 2, 3) - std::pow(0.7 - t / 2, 3));
  struct Case {
    const char* name;
    Expr model;
    double volume;
  };
  for (const Case& c : {Case{"shell 1.8 voxels thick", shell, shellVolume}, Case{"blocks 1.5 voxels apart", gap, 2 * 0.8 * 1.0 * 0.9}}) {
    const char* name = c.name;
    Result r = simplifyAndCheck(c.model, g, 0.1);
    figures(name, r, c.volume, r.area);
    EXPECT_NEAR(r.volume, c.volume, r.stats.errorBound * r.area + 1e-3 * c.volume) << name;
    EXPECT_EQ(mc::eulerCharacteristic(r.mesh.triangles, r.mesh.positions.size()), 4) << name;
    EXPECT_LT(r.mesh.triangles.size(), r.rawTriangles / 4) << name;
  }
}

// A tolerance whose error levels are no normal numbers (5e-324 voxels spun without end, an
// infinity too, in frep mesh, the Python module and a worker given such a job) is refused;
// the smallest and largest allowed ones simplify and stop.
TEST(MeshSimplify, RefusesTolerancesItsErrorLevelsCannotHold) {
  const GridSpec g = cubeGrid(1.2, 12);
  const TapePtr tape = Tape::compile(blockAt(0.013, -0.021, 0.007, 0.9, 0.7, 0.5), 3);
  const Mesh raw = meshGrid(tape, g, {}, 0);
  for (double tol : {5e-324, 1e-31, 1e31, 1e300, HUGE_VAL}) {
    Mesh m = raw;
    SimplifyOptions so;
    so.tolerance = tol;
    EXPECT_THROW(simplifyMesh(m, tape, g, so), std::invalid_argument) << tol;
  }
  for (double tol : {kMinSimplifyTolerance, kMaxSimplifyTolerance}) {
    Mesh m = raw;
    SimplifyOptions so;
    so.tolerance = tol;
    simplifyMesh(m, tape, g, so);
    EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "") << tol;
    EXPECT_LE(m.triangles.size(), raw.triangles.size()) << tol;
  }
}
