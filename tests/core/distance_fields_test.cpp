// Signed distance to polygons and triangle meshes (geometry/distance_fields.h) against
// independent references written here: brute-force closest points, winding numbers by angle and
// solid-angle sums, shoelace areas and divergence-theorem volumes, on random points and on the
// points that break parity tests (rays through vertices, lines along edges).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/geometry/distance_fields.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

// ---- independent 2D references ------------------------------------------------------------
double segDist(double px, double py, double ax, double ay, double bx, double by) {
  const double ex = bx - ax, ey = by - ay;
  double t = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey);
  t = std::max(0.0, std::min(1.0, t));
  return std::hypot(px - ax - t * ex, py - ay - t * ey);
}
double bruteDist2D(const std::vector<double>& v, double x, double y) {
  double d = INFINITY;
  const size_t n = v.size() / 2;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    d = std::min(d, segDist(x, y, v[2 * i], v[2 * i + 1], v[2 * j], v[2 * j + 1]));
  }
  return d;
}
// Winding number as the sum of the angles the edges subtend.
double winding2D(const std::vector<double>& v, double x, double y) {
  double s = 0.0;
  const size_t n = v.size() / 2;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    const double ax = v[2 * i] - x, ay = v[2 * i + 1] - y, bx = v[2 * j] - x, by = v[2 * j + 1] - y;
    s += std::atan2(ax * by - ay * bx, ax * bx + ay * by);
  }
  return s / (2 * M_PI);
}

// A star with 12 edges (non-convex), horizontal and vertical edges included via snapping.
std::vector<double> star12() {
  std::vector<double> v;
  for (int i = 0; i < 12; ++i) {
    const double r = i % 2 ? 0.45 : 1.0, a = 2 * M_PI * i / 12;
    v.push_back(std::round(r * std::cos(a) * 8) / 8);
    v.push_back(std::round(r * std::sin(a) * 8) / 8);
  }
  return v;
}

// ---- independent 3D references ------------------------------------------------------------
struct Soup {
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  uint32_t add(double x, double y, double z) {
    xyz.insert(xyz.end(), {x, y, z});
    return uint32_t(xyz.size() / 3 - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) { tris.insert(tris.end(), {a, b, c}); }
};

Soup cube(double h) {
  Soup s;
  for (int i = 0; i < 8; ++i) s.add(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& f : q) s.tri(f[0], f[1], f[2]), s.tri(f[0], f[2], f[3]);
  return s;
}

Soup torus(double R, double r, int nu, int nv) {
  Soup s;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, w = 2 * M_PI * j / nv;
      s.add((R + r * std::cos(w)) * std::cos(u), (R + r * std::cos(w)) * std::sin(u), r * std::sin(w));
    }
  auto id = [&](int i, int j) { return uint32_t((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      s.tri(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      s.tri(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return s;
}

// The 12-edge star extruded to z in [-0.5, 0.5]: concave vertical edges, fan-triangulated caps.
Soup starPrism() {
  const std::vector<double> v = star12();
  const uint32_t n = uint32_t(v.size() / 2);
  Soup s;
  for (int z = 0; z < 2; ++z)
    for (uint32_t i = 0; i < n; ++i) s.add(v[2 * i], v[2 * i + 1], z ? 0.5 : -0.5);
  const uint32_t c0 = s.add(0, 0, -0.5), c1 = s.add(0, 0, 0.5);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    s.tri(c0, j, i);
    s.tri(c1, n + i, n + j);
    s.tri(i, j, n + j);
    s.tri(i, n + j, n + i);
  }
  return s;
}

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Closest distance to a triangle: inside the prism over the face, the plane distance; else the
// nearest of the three edges.
double triDist(const double* p, const double* a, const double* b, const double* c) {
  double e0[3], e1[3], n[3], ap[3];
  for (int k = 0; k < 3; ++k) e0[k] = b[k] - a[k], e1[k] = c[k] - a[k], ap[k] = p[k] - a[k];
  n[0] = e0[1] * e1[2] - e0[2] * e1[1];
  n[1] = e0[2] * e1[0] - e0[0] * e1[2];
  n[2] = e0[0] * e1[1] - e0[1] * e1[0];
  const double nn = dot3(n, n);
  const double h = dot3(ap, n) / nn;
  double q[3];
  for (int k = 0; k < 3; ++k) q[k] = p[k] - h * n[k];
  // Barycentric test of the projection.
  auto side = [&](const double* u, const double* w) {
    double uw[3], uq[3], cr[3];
    for (int k = 0; k < 3; ++k) uw[k] = w[k] - u[k], uq[k] = q[k] - u[k];
    cr[0] = uw[1] * uq[2] - uw[2] * uq[1];
    cr[1] = uw[2] * uq[0] - uw[0] * uq[2];
    cr[2] = uw[0] * uq[1] - uw[1] * uq[0];
    return dot3(cr, n);
  };
  if (side(a, b) >= 0 && side(b, c) >= 0 && side(c, a) >= 0) return std::fabs(h) * std::sqrt(nn);
  auto seg = [&](const double* u, const double* w) {
    double uw[3], up[3];
    for (int k = 0; k < 3; ++k) uw[k] = w[k] - u[k], up[k] = p[k] - u[k];
    const double t = std::max(0.0, std::min(1.0, dot3(up, uw) / dot3(uw, uw)));
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (up[k] - t * uw[k]) * (up[k] - t * uw[k]);
    return std::sqrt(d2);
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}
double bruteDist3D(const Soup& s, const double* p) {
  double d = INFINITY;
  for (size_t t = 0; t < s.tris.size(); t += 3)
    d = std::min(d, triDist(p, &s.xyz[3 * s.tris[t]], &s.xyz[3 * s.tris[t + 1]], &s.xyz[3 * s.tris[t + 2]]));
  return d;
}
// Winding number by L'Huilier's theorem (spherical excess of each triangle seen from p).
double winding3D(const Soup& s, const double* p) {
  double sum = 0.0;
  for (size_t t = 0; t < s.tris.size(); t += 3) {
    double u[3][3];
    for (int c = 0; c < 3; ++c) {
      double l = 0;
      for (int k = 0; k < 3; ++k) u[c][k] = s.xyz[3 * s.tris[t + c] + k] - p[k], l += u[c][k] * u[c][k];
      l = std::sqrt(l);
      for (int k = 0; k < 3; ++k) u[c][k] /= l;
    }
    auto ang = [&](int i, int j) { return std::acos(std::max(-1.0, std::min(1.0, dot3(u[i], u[j])))); };
    const double a = ang(1, 2), b = ang(2, 0), c = ang(0, 1), sp = 0.5 * (a + b + c);
    const double e = 4 * std::atan(std::sqrt(std::max(0.0, std::tan(sp / 2) * std::tan((sp - a) / 2) *
                                                               std::tan((sp - b) / 2) * std::tan((sp - c) / 2))));
    double cr[3] = {u[1][1] * u[2][2] - u[1][2] * u[2][1], u[1][2] * u[2][0] - u[1][0] * u[2][2],
                    u[1][0] * u[2][1] - u[1][1] * u[2][0]};
    sum += dot3(u[0], cr) >= 0 ? e : -e;
  }
  return sum / (4 * M_PI);
}
double shoelace(const std::vector<double>& v) {
  double a = 0;
  const size_t n = v.size() / 2;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    a += 0.5 * (v[2 * i] * v[2 * j + 1] - v[2 * j] * v[2 * i + 1]);
  }
  return a;
}

// Points that defeat parity tests: on axis-parallel and random rays through every vertex, on
// the lines through edges (beyond their ends), plus random points in a box.
std::vector<std::array<double, 3>> hardPoints(const std::vector<double>& xyz, const std::vector<uint32_t>& edges,
                                              int dims, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.5, 1.5), t(-2.0, 2.0);
  std::vector<std::array<double, 3>> pts;
  const size_t nv = xyz.size() / dims;
  for (size_t i = 0; i < nv; ++i) {
    for (int axis = 0; axis < dims; ++axis)
      for (double s : {-0.7, -0.31, 0.23, 0.6}) {
        std::array<double, 3> p{0, 0, 0};
        for (int k = 0; k < dims; ++k) p[k] = xyz[dims * i + k];
        p[axis] += s;
        pts.push_back(p);
      }
  }
  for (size_t e = 0; e + 1 < edges.size(); e += 2)
    for (double s : {-1.3, -0.4, 1.25, 1.9}) {
      std::array<double, 3> p{0, 0, 0};
      for (int k = 0; k < dims; ++k) {
        const double a = xyz[dims * edges[e] + k], b = xyz[dims * edges[e + 1] + k];
        p[k] = a + s * (b - a);
      }
      pts.push_back(p);
    }
  for (int i = 0; i < 3000; ++i) pts.push_back({u(rng), u(rng), dims == 3 ? u(rng) : 0.0});
  return pts;
}

}  // namespace

TEST(PolygonField, DistanceMatchesBruteForceOnRandomPoints) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  // A random star-shaped polygon with many edges, so the BVH has depth.
  std::vector<double> v;
  for (int i = 0; i < 500; ++i) {
    const double a = 2 * M_PI * i / 500, r = 0.5 + 0.4 * std::uniform_real_distribution<double>(0, 1)(rng);
    v.push_back(r * std::cos(a));
    v.push_back(r * std::sin(a));
  }
  PolygonField f(v, "random star");
  for (int i = 0; i < 20000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const double d = bruteDist2D(v, p[0], p[1]);
    EXPECT_NEAR(std::fabs(f.value(p)), d, 1e-12 * (1 + d));
  }
}

TEST(PolygonField, SignMatchesWindingNumberOnVertexRaysAndEdgeLines) {
  std::mt19937 rng(11);
  for (bool reversed : {false, true}) {
    std::vector<double> v = star12();
    if (reversed)  // clockwise input: the field normalises the orientation
      for (size_t i = 0, k = v.size() / 2 - 1; i < k; ++i, --k) std::swap(v[2 * i], v[2 * k]), std::swap(v[2 * i + 1], v[2 * k + 1]);
    PolygonField f(v, "star");
    std::vector<uint32_t> edges;
    const uint32_t n = uint32_t(v.size() / 2);
    for (uint32_t i = 0; i < n; ++i) edges.insert(edges.end(), {i, (i + 1) % n});
    int errors = 0, checked = 0;
    for (auto& p : hardPoints(v, edges, 2, rng)) {
      const double fv = f.value(p.data());
      if (std::fabs(fv) < 1e-12) continue;  // on the boundary: no sign to compare
      const bool inside = std::fabs(winding2D(v, p[0], p[1])) > 0.5;
      errors += inside != (fv > 0);
      ++checked;
    }
    EXPECT_EQ(errors, 0) << "of " << checked;
    EXPECT_GT(checked, 3000);
  }
}

TEST(PolygonField, SampledAreaWithinOnePercentAndBoundsAreSound) {
  const std::vector<double> v = star12();
  auto field = std::make_shared<PolygonField>(v, "star");
  EXPECT_NEAR(field->area(), std::fabs(shoelace(v)), 1e-12);
  auto tape = Tape::compile(fieldExpr(field, Expr::x(0), Expr::x(1)), 2);
  // Batch evaluation of a 400 x 400 lattice.
  BatchEvaluator<double> be;
  const int N = 400;
  const double h = 2.4 / N;
  size_t inside = 0;
  PointEvaluator pe;
  for (int i = 0; i < N; ++i) {
    for (int j0 = 0; j0 < N; j0 += int(BatchEvaluator<double>::kBatch)) {
      const size_t cnt = std::min(size_t(N - j0), BatchEvaluator<double>::kBatch);
      be.reserve(*tape);
      double* xs = be.in(0);
      double* ys = be.in(1);
      for (size_t k = 0; k < cnt; ++k) xs[k] = -1.2 + (i + 0.5) * h, ys[k] = -1.2 + (j0 + k + 0.5) * h;
      const double* out = be.eval(*tape, cnt);
      for (size_t k = 0; k < cnt; ++k) {
        inside += out[k] >= 0;
        if ((i * 7 + j0 + k) % 97 == 0) {
          const double p[2] = {xs[k], ys[k]};
          ASSERT_EQ(out[k], pe.eval(*tape, p));
        }
      }
    }
  }
  EXPECT_NEAR(inside * h * h / field->area(), 1.0, 0.01);
  // Interval bounds contain every value in the box and are tight (width = 2 x half-diagonal).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.3, 1.3), w(0.0, 0.4);
  IntervalEvaluator ie;
  for (int b = 0; b < 300; ++b) {
    const double x0 = u(rng), y0 = u(rng), wx = w(rng), wy = w(rng);
    const Interval box[2] = {{x0, x0 + wx}, {y0, y0 + wy}};
    const Interval r = ie.eval(*tape, box);
    EXPECT_LE(r.hi - r.lo, std::hypot(wx, wy) * (1 + 1e-9) + 1e-12);
    for (int s = 0; s < 49; ++s) {
      const double p[2] = {x0 + wx * (s % 7) / 6.0, y0 + wy * (s / 7) / 6.0};
      const double fv = pe.eval(*tape, p);
      EXPECT_TRUE(fv >= r.lo && fv <= r.hi) << fv << " not in [" << r.lo << ", " << r.hi << "]";
    }
  }
}

TEST(PolygonField, RejectsDegenerateInput) {
  EXPECT_THROW(PolygonField({0, 0, 1, 1}, "two"), std::invalid_argument);
  EXPECT_THROW(PolygonField({0, 0, 1, 1, 2, 2}, "collinear"), std::invalid_argument);
  EXPECT_THROW(PolygonField({0, 0, 1, 0, 1}, "odd"), std::invalid_argument);
}

TEST(MeshField, DistanceMatchesBruteForceOnRandomPoints) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  for (const Soup& s : {cube(0.5), torus(0.8, 0.3, 40, 24), starPrism()}) {
    MeshField f(s.xyz, s.tris, "mesh");
    ASSERT_TRUE(f.check().closed());
    for (int i = 0; i < 4000; ++i) {
      const double p[3] = {u(rng), u(rng), u(rng)};
      const double d = bruteDist3D(s, p);
      ASSERT_NEAR(std::fabs(f.value(p)), d, 1e-12 * (1 + d));
    }
  }
}


// A cube of side 2h with every face cut into n x n squares: lattice points around it are
// equidistant from many triangles (faces, edges, corners), the hard case for tie-breaking.
Soup finelyCutCube(double h, int n) {
  Soup s;
  auto face = [&](int axis, double side) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    std::vector<uint32_t> id;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        double x[3];
        x[axis] = side, x[u] = -h + 2 * h * i / n, x[v] = -h + 2 * h * j / n;
        id.push_back(s.add(x[0], x[1], x[2]));
      }
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const uint32_t a = id[size_t(i * (n + 1) + j)], b = id[size_t((i + 1) * (n + 1) + j)];
        const uint32_t c = id[size_t((i + 1) * (n + 1) + j + 1)], d = id[size_t(i * (n + 1) + j + 1)];
        if (side > 0) s.tri(a, b, c), s.tri(a, c, d);
        else s.tri(a, c, b), s.tri(a, d, c);
      }
  };
  for (int axis = 0; axis < 3; ++axis) face(axis, h), face(axis, -h);
  return s;  // equal corners are welded by MeshField
}

// The query prunes by the thread's previous nearest triangle (warm start), by each triangle's
// plane and by the candidate cells of a lattice: none may change an answer. Lattice points
// around a finely cut cube (exact ties between faces, edges and corners) and random points
// near a torus: value, gradient (so the closest point chosen among ties) bit for bit the same
// through the cells and through the whole hierarchy, in order, shuffled, and interleaved with
// a second mesh; and the distance of the brute force.
TEST(MeshField, AnswersDoNotDependOnTheOrderOfQueriesOrTheCells) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const Soup cubeSoup = finelyCutCube(0.5, 6), torusSoup = torus(0.8, 0.3, 40, 24);
  MeshField c(cubeSoup.xyz, cubeSoup.tris, "cube"), t(torusSoup.xyz, torusSoup.tris, "torus");
  ASSERT_TRUE(c.check().closed());
  std::vector<std::array<double, 3>> pts;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) pts.push_back({0.125 * i, 0.125 * j, 0.125 * k});
  for (int i = 0; i < 3000; ++i) pts.push_back({u(rng), u(rng), 0.4 * u(rng)});
  struct Answer {
    double f, g[3];
  };
  auto ask = [](const MeshField& m, const std::array<double, 3>& p) {
    Answer a;
    a.f = m.gradient(p.data(), a.g);
    return a;
  };
  auto same = [](const Answer& a, const Answer& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  std::vector<Answer> cubeCells, torusCells;
  for (const auto& p : pts) cubeCells.push_back(ask(c, p));
  for (const auto& p : pts) torusCells.push_back(ask(t, p));
  std::vector<size_t> order(pts.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (bool cells : {true, false}) {
    MeshField::useCandidateCells(cells);
    for (size_t i = 0; i < pts.size(); ++i) ASSERT_TRUE(same(ask(c, pts[i]), cubeCells[i])) << "cube point " << i;
    for (size_t i : order) {
      ASSERT_TRUE(same(ask(c, pts[i]), cubeCells[i])) << "cube point " << i << (cells ? " (cells)" : " (hierarchy)");
      ASSERT_TRUE(same(ask(t, pts[i]), torusCells[i])) << "torus point " << i << (cells ? " (cells)" : " (hierarchy)");
    }
  }
  MeshField::useCandidateCells(true);
  // classValue: the class of its cell where no triangle meets the cell, else the value.
  for (size_t i = 0; i < pts.size(); ++i)
    for (const MeshField* m : {&c, &t}) {
      const double f = m->value(pts[i].data()), k = m->classValue(pts[i].data());
      ASSERT_EQ(f > 0, k > 0) << m->describe() << " point " << i;
      ASSERT_EQ(f < 0, k < 0) << m->describe() << " point " << i;
    }
  for (size_t i = 0; i < pts.size(); i += 7) {
    ASSERT_NEAR(std::fabs(cubeCells[i].f), bruteDist3D(cubeSoup, pts[i].data()), 1e-12);
    ASSERT_NEAR(std::fabs(torusCells[i].f), bruteDist3D(torusSoup, pts[i].data()), 1e-12);
  }
}

// A cell's list is walked nearest to its centre first and a query stops at the first triangle
// whose |c - T| - |p - c| exceeds its best distance. Pairs of points a hair either side of
// offsets of a fine torus 1 to 4 lattice cells out and in (the simplifier's inside/outside
// pairs, where the lists are longest): the same bits through the cells as through the whole
// hierarchy (a stop by |c - T| alone fails here), and the brute force's distance.
TEST(MeshField, NearFirstCellListsStopWithTheSameAnswers) {
  const Soup soup = torus(0.8, 0.3, 64, 32);
  MeshField m(soup.xyz, soup.tris, "fine torus");
  const double cell = 2.2 / 64;  // the lattice: 64 cells along the longest side
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), offset(-4 * cell, 4 * cell);
  std::vector<std::array<double, 3>> pts;
  for (int i = 0; i < 2000; ++i) {
    const double u = angle(rng), w = angle(rng), s = offset(rng);
    const double n[3] = {std::cos(w) * std::cos(u), std::cos(w) * std::sin(u), std::sin(w)};
    for (double e : {-1e-3, 1e-3}) {
      const double t = 0.3 + s + e;
      pts.push_back({0.8 * std::cos(u) + t * n[0], 0.8 * std::sin(u) + t * n[1], t * n[2]});
    }
  }
  std::vector<std::array<double, 4>> cells;
  for (const auto& p : pts) {
    std::array<double, 4> a;
    a[0] = m.gradient(p.data(), &a[1]);
    cells.push_back(a);
  }
  MeshField::useCandidateCells(false);
  for (size_t i = 0; i < pts.size(); ++i) {
    std::array<double, 4> a;
    a[0] = m.gradient(pts[i].data(), &a[1]);
    ASSERT_EQ(std::memcmp(&a, &cells[i], sizeof a), 0) << "point " << i;
  }
  MeshField::useCandidateCells(true);
  for (size_t i = 0; i < pts.size(); i += 3) ASSERT_NEAR(std::fabs(cells[i][0]), bruteDist3D(soup, pts[i].data()), 1e-12);
}

// A mesh of at most 16 triangles is scanned whole, this thread's last nearest triangle first:
// on the lattice points around a cube (12 triangles; ties between faces, edges and corners) the
// value and gradient (the closest point chosen among ties) are bit for bit the same in order,
// shuffled and interleaved with the torus's queries, and the distance is the brute force's.
TEST(MeshField, SmallMeshAnswersDoNotDependOnTheOrderOfQueries) {
  std::mt19937 rng(23);
  const Soup cubeSoup = cube(0.5), torusSoup = torus(0.8, 0.3, 40, 24);
  MeshField c(cubeSoup.xyz, cubeSoup.tris, "cube"), t(torusSoup.xyz, torusSoup.tris, "torus");
  std::vector<std::array<double, 3>> pts;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) pts.push_back({0.125 * i, 0.125 * j, 0.125 * k});
  auto ask = [](const MeshField& m, const std::array<double, 3>& p) {
    std::array<double, 4> a;
    a[0] = m.gradient(p.data(), a.data() + 1);
    return a;
  };
  std::vector<std::array<double, 4>> ref;
  for (const auto& p : pts) ref.push_back(ask(c, p));
  std::vector<size_t> order(pts.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (int round = 0; round < 2; ++round) {
    std::shuffle(order.begin(), order.end(), rng);
    for (size_t i : order) {
      ASSERT_TRUE(std::memcmp(ask(c, pts[i]).data(), ref[i].data(), sizeof ref[i]) == 0) << "cube point " << i;
      if (round == 1) ask(t, pts[order[(i * 7) % order.size()]]);  // another field's queries between
    }
  }
  for (size_t i = 0; i < pts.size(); ++i) ASSERT_NEAR(std::fabs(ref[i][0]), bruteDist3D(cubeSoup, pts[i].data()), 1e-12);
}

TEST(MeshField, SignMatchesWindingNumberOnVertexRaysAndEdgeLines) {
  std::mt19937 rng(13);
  for (const Soup& s : {cube(0.5), torus(0.8, 0.3, 24, 16), starPrism()}) {
    MeshField f(s.xyz, s.tris, "mesh");
    std::vector<uint32_t> edges;
    for (size_t t = 0; t < s.tris.size(); t += 3)
      for (int c = 0; c < 3; ++c) edges.insert(edges.end(), {s.tris[t + c], s.tris[t + (c + 1) % 3]});
    int errors = 0, checked = 0, gwnErrors = 0;
    for (auto& p : hardPoints(s.xyz, edges, 3, rng)) {
      const double fv = f.value(p.data());
      if (std::fabs(fv) < 1e-12) continue;
      const bool inside = winding3D(s, p.data()) > 0.5;
      errors += inside != (fv > 0);
      gwnErrors += inside != (f.windingNumber(p.data()) > 0.5);
      ++checked;
    }
    EXPECT_EQ(errors, 0) << "of " << checked;
    EXPECT_EQ(gwnErrors, 0) << "of " << checked;
    EXPECT_GT(checked, 3000);
  }
}

TEST(MeshField, SampledVolumeWithinOnePercentOfDivergenceTheorem) {
  for (const Soup& s : {torus(0.8, 0.3, 64, 32), starPrism()}) {
    auto field = std::make_shared<MeshField>(s.xyz, s.tris, "mesh");
    auto tape = Tape::compile(fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2)), 3);
    GridSpec g = GridSpec::fromBounds({-1.2, -1.2, -0.6}, {1.2, 1.2, 0.6}, 160);
    SampleResult r = sample(tape, g);
    const double vol = field->volume();
    EXPECT_GT(vol, 0.0);
    EXPECT_NEAR(insideVolume(r) / vol, 1.0, 0.01);
    // Sparse: the interval bound keeps the point evaluations near the surface.
    EXPECT_LT(double(r.stats.pointEvals), 0.35 * double(r.stats.denseEvals));
  }
  // Analytic check of the cube: the lattice count of [-0.5, 0.5]^3 at voxel 1/64 is exact.
  Soup c = cube(0.5);
  auto field = std::make_shared<MeshField>(c.xyz, c.tris, "cube");
  EXPECT_NEAR(field->volume(), 1.0, 1e-12);
}

TEST(MeshField, IntervalBoundsAreSoundAndTight) {
  Soup s = torus(0.8, 0.3, 32, 16);
  auto field = std::make_shared<MeshField>(s.xyz, s.tris, "torus");
  auto tape = Tape::compile(fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2)), 3);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.3, 1.3), w(0.0, 0.5);
  IntervalEvaluator ie;
  PointEvaluator pe;
  for (int b = 0; b < 200; ++b) {
    double lo[3], wd[3];
    for (int k = 0; k < 3; ++k) lo[k] = u(rng), wd[k] = w(rng);
    const Interval box[3] = {{lo[0], lo[0] + wd[0]}, {lo[1], lo[1] + wd[1]}, {lo[2], lo[2] + wd[2]}};
    const Interval r = ie.eval(*tape, box);
    EXPECT_LE(r.hi - r.lo, std::sqrt(wd[0] * wd[0] + wd[1] * wd[1] + wd[2] * wd[2]) * (1 + 1e-9) + 1e-12);
    for (int k = 0; k < 64; ++k) {
      const double p[3] = {lo[0] + wd[0] * (k & 3) / 3.0, lo[1] + wd[1] * ((k >> 2) & 3) / 3.0,
                           lo[2] + wd[2] * (k >> 4) / 3.0};
      const double fv = pe.eval(*tape, p);
      EXPECT_TRUE(fv >= r.lo && fv <= r.hi);
    }
  }
}

TEST(MeshField, BoxesThatMissTheTrianglesKeepOneSign) {
  // Boxes near the surface of a closed torus: where a box touches no leaf box of the hierarchy
  // the bound excludes 0 even when the Lipschitz bound f(c) +- half-diagonal does not; sound at
  // every sampled point either way.
  Soup s = torus(0.8, 0.3, 48, 24);
  auto field = std::make_shared<MeshField>(s.xyz, s.tris, "torus");
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ang(0, 2 * M_PI), off(-0.2, 0.2), w(0.01, 0.12);
  int tighter = 0;
  for (int b = 0; b < 400; ++b) {
    const double a = ang(rng), v = ang(rng), d = 0.3 + off(rng), h = w(rng);
    const double c[3] = {(0.8 + d * std::cos(v)) * std::cos(a), (0.8 + d * std::cos(v)) * std::sin(a), d * std::sin(v)};
    const Interval box[3] = {{c[0] - h, c[0] + h}, {c[1] - h, c[1] + h}, {c[2] - h, c[2] + h}};
    const Interval r = field->bound(box), lip = field->DistanceField::bound(box);
    EXPECT_TRUE(r.lo >= lip.lo && r.hi <= lip.hi);
    if ((r.lo > 0 || r.hi < 0) && !(lip.lo > 0 || lip.hi < 0)) ++tighter;
    for (int k = 0; k < 125; ++k) {
      const double p[3] = {box[0].lo + 2 * h * (k % 5) / 4.0, box[1].lo + 2 * h * ((k / 5) % 5) / 4.0,
                           box[2].lo + 2 * h * (k / 25) / 4.0};
      const double fv = field->value(p);
      EXPECT_TRUE(fv >= r.lo && fv <= r.hi) << fv << " not in [" << r.lo << ", " << r.hi << "]";
    }
  }
  EXPECT_GT(tighter, 5);  // 13 of 400 with this seed
}

TEST(MeshField, OpenMeshReportsEdgesAndSignsByWindingNumber) {
  Soup s = cube(0.5);
  s.tris.resize(s.tris.size() - 3);  // drop one triangle: 3 open edges
  MeshField f(s.xyz, s.tris, "open cube");
  EXPECT_FALSE(f.check().closed());
  EXPECT_EQ(f.check().openEdges, 3u);
  const double in[3] = {0.1, 0.05, -0.2}, out[3] = {1.0, 0.2, 0.3};
  EXPECT_GT(f.value(in), 0.0);
  EXPECT_LT(f.value(out), 0.0);
}

TEST(MeshField, WeldsTriangleSoups) {
  Soup c = cube(0.5), soup;
  for (uint32_t i : c.tris) soup.add(c.xyz[3 * i], c.xyz[3 * i + 1], c.xyz[3 * i + 2]);
  for (uint32_t i = 0; i < soup.xyz.size() / 3; ++i) soup.tris.push_back(i);
  MeshField f(soup.xyz, soup.tris, "soup");
  EXPECT_TRUE(f.check().closed());
  EXPECT_EQ(f.numVertices(), 8u);
  // Mixed windings (every third triangle flipped) and an inside-out whole are reoriented.
  for (bool insideOut : {false, true}) {
    Soup mixed = cube(0.5);
    for (size_t t = 0; t < mixed.tris.size(); t += 3)
      if ((t / 3) % 3 == 0 || insideOut) std::swap(mixed.tris[t + 1], mixed.tris[t + 2]);
    MeshField g(mixed.xyz, mixed.tris, "mixed");
    EXPECT_NEAR(g.volume(), 1.0, 1e-12);
    const double in[3] = {0.1, 0.2, 0.3}, out[3] = {0.7, 0.2, 0.3};
    EXPECT_NEAR(g.value(in), 0.2, 1e-12);
    EXPECT_NEAR(g.value(out), -0.2, 1e-12);
  }
}

TEST(BezierLoop, TessellationIsWithinDeltaOfTheCurve) {
  // A closed degree-3 composite curve of two arcs (a rounded lens).
  const std::vector<double> ctrl = {-1, 0, -0.5, 1, 0.5, 1, 1, 0, 0.5, -1, -0.5, -1, -1, 0};
  for (double delta : {0.05, 0.01, 0.002}) {
    std::vector<double> poly = tessellateBezierLoop(ctrl, 3, 5, delta);
    PolygonField f(poly, "lens");
    double worst = 0;
    for (int a = 0; a < 2; ++a)
      for (int i = 0; i <= 2000; ++i) {
        double q[3] = {0, 0, 0};
        bezierPoint(&ctrl[6 * a], 3, 2, i / 2000.0, q);
        worst = std::max(worst, std::fabs(f.value(q)));
      }
    EXPECT_LE(worst, delta * 1.01) << "delta " << delta;
  }
}

TEST(BezierLoop, RejectsBadControlArrays) {
  EXPECT_THROW(tessellateBezierLoop({0, 0, 1, 0, 1, 1, 0, 0}, 2, 4, 0.01), std::invalid_argument);  // count
  EXPECT_THROW(tessellateBezierLoop({0, 0, 1, 0, 1, 1, 0, 1}, 3, 4, 0.01), std::invalid_argument);  // open
  EXPECT_THROW(tessellateBezierLoop({0, 0, 0, 0, 0, 0, 0, 0}, 3, 4, 0.01), std::invalid_argument);  // degenerate
}

namespace {
// Six bicubic patches on the faces of [-h, h]^3 whose interior control points bulge outward by
// `bulge`: neighbours share their boundary control points, so the surface is closed.
std::vector<double> pillowPatches(double h, double bulge, bool outward) {
  std::vector<double> c;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      for (int i = 0; i <= 3; ++i)
        for (int j = 0; j <= 3; ++j) {
          // (u, v) along (a1, a2) on the + side and (a2, a1) on the - side: u x v points out.
          const double s = -h + 2 * h * i / 3.0, t = -h + 2 * h * j / 3.0;
          double p[3];
          const bool swapUV = (side < 0) == outward;
          p[a1] = swapUV ? t : s;
          p[a2] = swapUV ? s : t;
          const bool interior = i > 0 && i < 3 && j > 0 && j < 3;
          p[axis] = side * (h + (interior ? bulge : 0.0));
          c.insert(c.end(), p, p + 3);
        }
    }
  return c;
}
}  // namespace

TEST(BezierPatches, ClosedWatertightWithinDeltaAndVolumeByDivergence) {
  for (bool outward : {true, false}) {  // either orientation of the patches is accepted
    for (double delta : {0.01, 0.002}) {
      const std::vector<double> c = pillowPatches(0.5, 0.15, outward);
      TriangleMesh m = tessellateBezierPatches(c, 3, 3, 2, delta);
      auto f = std::make_shared<MeshField>(m.xyz, m.tris, "pillow");
      ASSERT_TRUE(f->check().closed()) << f->check().openEdges << " open edges";
      EXPECT_GT(f->volume(), 1.0);
      // Every surface point is within delta of the tessellation.
      double worst = 0;
      for (size_t p = 0; p < 6; ++p)
        for (int i = 0; i <= 40; ++i)
          for (int j = 0; j <= 40; ++j) {
            std::vector<double> row(48);
            std::copy(c.begin() + 48 * p, c.begin() + 48 * (p + 1), row.begin());
            // S(u, v) by de Casteljau over rows then the column, as an independent evaluation.
            double col[12], q[3];
            for (int jj = 0; jj <= 3; ++jj) {
              double r[12];
              for (int ii = 0; ii <= 3; ++ii)
                for (int k = 0; k < 3; ++k) r[3 * ii + k] = row[3 * (ii * 4 + jj) + k];
              bezierPoint(r, 3, 3, i / 40.0, &col[3 * jj]);
            }
            bezierPoint(col, 3, 3, j / 40.0, q);
            worst = std::max(worst, std::fabs(f->value(q)));
          }
      EXPECT_LE(worst, delta) << "delta " << delta;
    }
  }
  // Flat patches (no bulge): exactly the unit cube.
  TriangleMesh cubeMesh = tessellateBezierPatches(pillowPatches(0.5, 0.0, true), 3, 3, 3, 0.01);
  MeshField cube(cubeMesh.xyz, cubeMesh.tris, "cube");
  EXPECT_TRUE(cube.check().closed());
  EXPECT_NEAR(cube.volume(), 1.0, 1e-12);
  EXPECT_THROW(tessellateBezierPatches(std::vector<double>(47, 0.0), 3, 3, 2, 0.01), std::invalid_argument);
  EXPECT_THROW(tessellateBezierPatches(std::vector<double>(48, 1.0), 3, 3, 2, 0.01), std::invalid_argument);
}
