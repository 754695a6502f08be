// Sweeps of closed triangle meshes by translation along a polyline (path_sweep.h through
// mesh_convex_sum.h with segments for the tool): a box mesh along an axis (a longer box) and a
// diagonal (a zonotope), a triangular prism along its top face's plane (flat prisms T ⊕ d) and
// barely off it, an L prism along two segments against the distance to the moving L minimised
// over the time by golden-section search, and meshes of the results closed with the formulas'
// volumes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "core/mesh_checks.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/geometry/distance_fields.h"
#include "frep/geometry/vec3.h"
#include "frep/meshing/mesh.h"
#include "frep/minkowski_algebra/path_sweep.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/primitives/ops.h"

using namespace frep;
namespace mc = mesh_checks;

namespace {

using V3 = std::array<double, 3>;
using mesh_models::X;
using mesh_models::Y;
using mesh_models::Z;
using vec3::cross;
using vec3::dot;

double eval(const Expr& e, const V3& p) {
  TapePtr t = Tape::compile(e, 3);
  PointEvaluator pe;
  return pe.eval(*t, p.data());
}

Expr meshExpr(const std::vector<double>& xyz, const std::vector<uint32_t>& tris, const char* name) {
  auto m = std::make_shared<MeshField>(xyz, tris, name);
  EXPECT_TRUE(m->check().closed());
  return fieldExpr(m, X(), Y(), Z());
}

// The axis box [lo, hi] as 12 triangles, outward.
Expr boxMesh(const V3& lo, const V3& hi) {
  const int c[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const uint32_t t[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::vector<double> xyz;
  for (const auto& k : c)
    for (size_t a = 0; a < 3; ++a) xyz.push_back(k[a] ? hi[a] : lo[a]);
  std::vector<uint32_t> tris;
  for (const auto& k : t) tris.insert(tris.end(), k, k + 3);
  return meshExpr(xyz, tris, "box");
}

// The extrusion of the counter-clockwise polygon poly (fanned from its vertex fan) over z in
// [0, h]: a closed prism.
Expr prismMesh(const std::vector<std::array<double, 2>>& poly, const std::vector<std::array<uint32_t, 3>>& cap,
               double h, const char* name) {
  std::vector<double> xyz;
  for (double z : {0.0, h})
    for (const auto& p : poly) xyz.insert(xyz.end(), {p[0], p[1], z});
  const uint32_t n = uint32_t(poly.size());
  std::vector<uint32_t> tris;
  for (const auto& t : cap) {
    tris.insert(tris.end(), {t[0] + n, t[1] + n, t[2] + n});  // top, outward +z
    tris.insert(tris.end(), {t[0], t[2], t[1]});              // bottom, outward -z
  }
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    tris.insert(tris.end(), {i, j, j + n});
    tris.insert(tris.end(), {i, j + n, i + n});
  }
  return meshExpr(xyz, tris, name);
}

// The exact signed distance of the axis box [lo, hi] (positive inside).
double boxDistance(const V3& p, const V3& lo, const V3& hi) {
  double out = 0, in = -INFINITY;
  for (size_t i = 0; i < 3; ++i) {
    const double c = 0.5 * (lo[i] + hi[i]), h = 0.5 * (hi[i] - lo[i]);
    const double q = std::abs(p[i] - c) - h;
    out += q > 0 ? q * q : 0;
    in = std::max(in, q);
  }
  return out > 0 ? -std::sqrt(out) : -in;
}

// min over t in [0, 1] of dist(p - (a + t (b - a)), K) for a convex K's unsigned distance dist:
// convex in t, golden-section search.
template <typename Dist>
double sweptDistance(const V3& p, const V3& a, const V3& b, Dist&& dist) {
  auto at = [&](double t) {
    return dist(V3{p[0] - a[0] - t * (b[0] - a[0]), p[1] - a[1] - t * (b[1] - a[1]), p[2] - a[2] - t * (b[2] - a[2])});
  };
  double l = 0, h = 1;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 200; ++i) {
    const double m1 = h - g * (h - l), m2 = l + g * (h - l);
    if (at(m1) <= at(m2)) h = m2;
    else l = m1;
  }
  return std::min({at(0), at(1), at(0.5 * (l + h))});
}

std::string where(const V3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", p[0], p[1], p[2]);
  return buf;
}

double meshVolume(const Expr& f, const V3& lo, const V3& hi, int res, bool* closed) {
  Mesh m = meshGrid(Tape::compile(f, 3), GridSpec::fromBounds(lo, hi, res), {}, 32);
  *closed = mc::checkEdgePairs(m.triangles, m.positions.size()).empty();
  return mc::enclosedVolume(m.positions, m.triangles);
}

}  // namespace

// A box mesh along an axis is the longer box: exact signed distance outside, the sign inside,
// the volume of its mesh. Every face parallel to the path gives flat cells (T ⊕ d in T's plane).
TEST(MeshPathSweep, BoxMeshAlongAnAxisIsTheLongerBox) {
  const V3 lo{-0.3, -0.2, -0.25}, hi{0.3, 0.2, 0.25};
  Expr swept;
  ASSERT_TRUE(minkowski::translationSweep(boxMesh(lo, hi), {{0, 0, 0}, {1.2, 0, 0}}, &swept));
  const auto described = minkowski::describeExact(swept);
  ASSERT_EQ(described.size(), 1u);
  EXPECT_NE(described[0].find("exact Minkowski sum sweep of box (12 triangles) along a path of 2 points (1 segment) "
                              "as the union of the mesh's translate and"),
            std::string::npos)
      << described[0];
  EXPECT_NE(described[0].find("boundary pieces of triangle ⊕ segment sums"), std::string::npos) << described[0];
  const V3 slo = lo, shi{hi[0] + 1.2, hi[1], hi[2]};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.8, 1.9);
  int outside = 0, inside = 0;
  for (int i = 0; i < 3000; ++i) {
    V3 p{u(rng), 0.6 * u(rng), 0.6 * u(rng)};
    if (i % 3 == 0) p[size_t(1 + i % 2)] = i % 4 < 2 ? lo[size_t(1 + i % 2)] : hi[size_t(1 + i % 2)];  // face planes
    const double exact = boxDistance(p, slo, shi), f = eval(swept, p);
    if (std::abs(exact) < 1e-12) {
      EXPECT_GE(f, -1e-12) << where(p);
      continue;
    }
    ASSERT_EQ(f >= 0, exact > 0) << where(p) << " f " << f << " exact " << exact;
    if (exact < 0) {
      ++outside;
      EXPECT_NEAR(f, exact, 1e-9 * (1 + std::abs(exact))) << where(p);
    } else {
      ++inside;
      EXPECT_LE(f, exact + 1e-12) << where(p);
    }
  }
  EXPECT_GT(outside, 1500);
  EXPECT_GT(inside, 100);
  bool closed = false;
  const double volume = (shi[0] - slo[0]) * (shi[1] - slo[1]) * (shi[2] - slo[2]);
  EXPECT_NEAR(meshVolume(swept, {-0.5, -0.4, -0.4}, {1.7, 0.4, 0.4}, 97, &closed), volume, 0.003 * volume);
  EXPECT_TRUE(closed);
}

// Along a diagonal the box sweeps the zonotope of its three edges and the path d: facet normals
// g_i × g_j, support u · c + Σ |u · g_i| / 2 (its depth inside), volume Σ |det(g_i, g_j, g_k)|.
TEST(MeshPathSweep, BoxMeshAlongADiagonalIsTheZonotope) {
  const V3 lo{-0.3, -0.2, -0.25}, hi{0.3, 0.2, 0.25}, d{0.9, 0.7, 0.5};
  Expr swept;
  ASSERT_TRUE(minkowski::translationSweep(boxMesh(lo, hi), {{0, 0, 0}, d}, &swept));
  const std::vector<V3> gens = {{hi[0] - lo[0], 0, 0}, {0, hi[1] - lo[1], 0}, {0, 0, hi[2] - lo[2]}, d};
  V3 centre{0.5 * (lo[0] + hi[0] + d[0]), 0.5 * (lo[1] + hi[1] + d[1]), 0.5 * (lo[2] + hi[2] + d[2])};
  std::vector<std::pair<V3, double>> planes;  // u . x <= h
  for (size_t i = 0; i < gens.size(); ++i)
    for (size_t j = i + 1; j < gens.size(); ++j) {
      V3 n = cross(gens[i], gens[j]);
      const double l = std::sqrt(dot(n, n));
      for (double& x : n) x /= l;
      for (double s : {1.0, -1.0}) {
        const V3 un{s * n[0], s * n[1], s * n[2]};
        double h = dot(un, centre);
        for (const V3& g : gens) h += 0.5 * std::abs(dot(un, g));
        planes.push_back({un, h});
      }
    }
  // Inside, the depth is the least facet distance; outside, the distance to the box moved along
  // d, minimised over the time.
  auto boxDist = [&](const V3& q) { return std::max(0.0, -boxDistance(q, lo, hi)); };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.8, 1.6);
  int outside = 0, inside = 0;
  for (int i = 0; i < 3000; ++i) {
    const V3 p{u(rng), u(rng), u(rng)};
    double depth = INFINITY;
    for (const auto& [un, h] : planes) depth = std::min(depth, h - dot(un, p));
    const double exact = depth > 0 ? depth : -sweptDistance(p, {0, 0, 0}, d, boxDist), f = eval(swept, p);
    if (std::abs(exact) < 1e-9) continue;
    ASSERT_EQ(f >= 0, exact > 0) << where(p);
    if (exact < 0) {
      ++outside;
      EXPECT_NEAR(f, exact, 1e-9) << where(p);
    } else {
      ++inside;
      EXPECT_LE(f, exact + 1e-9) << where(p);
      EXPECT_GT(f, 0) << where(p);
    }
  }
  EXPECT_GT(outside, 1500);
  EXPECT_GT(inside, 100);
  double volume = 0;
  for (size_t i = 0; i < 4; ++i)
    for (size_t j = i + 1; j < 4; ++j)
      for (size_t k = j + 1; k < 4; ++k) volume += std::abs(dot(gens[i], cross(gens[j], gens[k])));
  bool closed = false;
  EXPECT_NEAR(meshVolume(swept, {-0.5, -0.4, -0.4}, {1.4, 1.1, 0.9}, 97, &closed), volume, 0.003 * volume);
  EXPECT_TRUE(closed);
}

// A triangular prism moved along its top and bottom faces' plane: each cap triangle T gives a
// flat T ⊕ d (a quadrilateral), whose box holds points of the plane outside it. There the field
// must be the distance to the sweep, not 0 (the planes ±n_T alone hold the whole plane): points
// on both cap planes, against the convex prism's distance moved along d, minimised over the time.
// The same a hair off the plane (a prism of 1e-8 thickness) and well off it.
TEST(MeshPathSweep, PathInAFacesPlaneKeepsTheFieldExact) {
  const double h = 0.5;
  const Expr prism = prismMesh({{0, 0}, {1, 0}, {0, 1}}, {{0, 1, 2}}, h, "wedge");
  // The distance to the prism, a product: the triangle's in (x, y) and the slab's in z.
  auto dist = [&](const V3& q) {
    double x = q[0], y = q[1];
    auto clampSeg = [](double ax, double ay, double bx, double by, double px, double py, double& ox, double& oy) {
      const double dx = bx - ax, dy = by - ay;
      const double t = std::clamp(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      ox = ax + t * dx, oy = ay + t * dy;
    };
    if (!(x >= 0 && y >= 0 && x + y <= 1)) {
      double best = INFINITY, bx = 0, by = 0;
      const double c[3][2] = {{0, 0}, {1, 0}, {0, 1}};
      for (int k = 0; k < 3; ++k) {
        double ox, oy;
        clampSeg(c[k][0], c[k][1], c[(k + 1) % 3][0], c[(k + 1) % 3][1], q[0], q[1], ox, oy);
        const double e = std::hypot(q[0] - ox, q[1] - oy);
        if (e < best) best = e, bx = ox, by = oy;
      }
      x = bx, y = by;
    }
    const double dz = std::max({0.0, -q[2], q[2] - h});
    return std::sqrt((q[0] - x) * (q[0] - x) + (q[1] - y) * (q[1] - y) + dz * dz);
  };
  for (const V3 d : {V3{1, 0, 0}, V3{0.8, 0.6, 0}, V3{1, 0, 1e-8}, V3{1, 0, 0.3}}) {
    Expr swept;
    ASSERT_TRUE(minkowski::translationSweep(prism, {{0, 0, 0}, d}, &swept));
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(-0.5, 2.2);
    int outside = 0;
    for (int i = 0; i < 1500; ++i) {
      V3 p{u(rng), u(rng), 0.5 * u(rng)};
      if (i % 2 == 0) p[2] = i % 4 == 0 ? 0 : h + (i % 8 == 2 ? d[2] : 0);  // the caps' planes
      const double exact = sweptDistance(p, {0, 0, 0}, d, dist), f = eval(swept, p);
      if (exact > 1e-9) {
        ++outside;
        EXPECT_NEAR(f, -exact, 1e-9 * (1 + exact)) << where(p) << " d " << where(d);
      } else {
        EXPECT_GE(f, -1e-9) << where(p) << " d " << where(d);
      }
    }
    EXPECT_GT(outside, 700) << where(d);
  }
}

// An L prism (non-convex, the union of two blocks) along an L-shaped path of two segments: the
// field against the distance to the moving L minimised over the time (per block and segment,
// convex in t), and the sign inside.
TEST(MeshPathSweep, LPrismAlongTwoSegmentsIsExactOutside) {
  const double h = 0.4;
  const Expr ell = prismMesh({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}},
                             {{3, 4, 5}, {3, 5, 0}, {3, 0, 1}, {3, 1, 2}}, h, "L prism");
  const std::vector<V3> path = {{0, 0, 0}, {0.7, 0.3, 0.5}, {0.7, 1.5, 0.2}};
  Expr swept;
  ASSERT_TRUE(minkowski::translationSweep(ell, path, &swept));
  const auto described = minkowski::describeExact(swept);
  ASSERT_EQ(described.size(), 1u);
  EXPECT_NE(described[0].find("sweep of L prism (20 triangles) along a path of 3 points (2 segments)"),
            std::string::npos)
      << described[0];
  const V3 b1lo{0, 0, 0}, b1hi{2, 1, h}, b2lo{0, 0, 0}, b2hi{1, 2, h};
  auto dist1 = [&](const V3& q) { return std::max(0.0, -boxDistance(q, b1lo, b1hi)); };
  auto dist2 = [&](const V3& q) { return std::max(0.0, -boxDistance(q, b2lo, b2hi)); };
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.7, 3.9);
  int outside = 0, inside = 0;
  for (int i = 0; i < 2500; ++i) {
    const V3 p{u(rng), u(rng), 0.4 * u(rng)};
    double exact = INFINITY;
    for (size_t s = 0; s + 1 < path.size(); ++s)
      exact = std::min(
          {exact, sweptDistance(p, path[s], path[s + 1], dist1), sweptDistance(p, path[s], path[s + 1], dist2)});
    const double f = eval(swept, p);
    if (exact > 1e-9) {
      ++outside;
      EXPECT_NEAR(f, -exact, 1e-9 * (1 + exact)) << where(p);
    } else {
      ++inside;
      EXPECT_GE(f, -1e-9) << where(p);
    }
  }
  EXPECT_GT(outside, 1000);
  EXPECT_GT(inside, 300);
}

// A repeated point adds no segment, and a path of one point moves the mesh there (its cells are
// the flat triangles themselves): the box's exact distance outside, its sign inside.
TEST(MeshPathSweep, RepeatedPointsAndASinglePoint) {
  const V3 lo{-0.3, -0.2, -0.25}, hi{0.3, 0.2, 0.25};
  const Expr box = boxMesh(lo, hi);
  Expr once, twice, moved;
  ASSERT_TRUE(minkowski::translationSweep(box, {{0, 0, 0}, {0.5, 0.5, 0}}, &once));
  ASSERT_TRUE(minkowski::translationSweep(box, {{0, 0, 0}, {0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 0}}, &twice));
  ASSERT_TRUE(minkowski::translationSweep(box, {{0.4, -0.1, 0.2}}, &moved));
  EXPECT_NE(minkowski::describeExact(twice)[0].find("along a path of 4 points (1 segment)"), std::string::npos);
  const V3 mlo{lo[0] + 0.4, lo[1] - 0.1, lo[2] + 0.2}, mhi{hi[0] + 0.4, hi[1] - 0.1, hi[2] + 0.2};
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u(-0.8, 1.2);
  for (int i = 0; i < 1000; ++i) {
    const V3 p{u(rng), u(rng), u(rng)};
    EXPECT_EQ(eval(once, p), eval(twice, p)) << where(p);
    const double exact = boxDistance(p, mlo, mhi), f = eval(moved, p);
    if (exact < 0) EXPECT_NEAR(f, exact, 1e-12) << where(p);
    else EXPECT_GE(f, 0) << where(p);
  }
}
