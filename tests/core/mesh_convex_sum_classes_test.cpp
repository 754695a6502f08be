// Closed mesh ⊕ / ⊖ convex polytope (mesh_convex_sum.h): the classes of points, by every path
// that gives one — sign-only batches and samples, the lattice cells' recorded classes, a cell's
// facets and lead plane — against the values and closed forms, and the field's interval bounds.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "core/mesh_convex_sum_shapes.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

using namespace frep;
using namespace frep::mesh_convex_sum_shapes;

TEST(MeshConvexSum, SignOnlyBatchesClassifyEveryPointAsTheValues) {
  // The simplifier's batches ask only inside/outside (BatchEvaluator::setFieldSignsOnly): the
  // sum skips its distance to the boundary pieces there, and must keep every class, of the sum
  // and of the difference (whose inside is the negated outside).
  Expr sum, diff;
  ASSERT_TRUE(lPrismSumAndDifference(sum, diff));
  for (const Expr* e : {&sum, &diff}) {
    TapePtr tape = Tape::compile(*e, 3);
    BatchEvaluator<double> values, signs;
    signs.setFieldSignsOnly(true);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-0.8, 2.8);
    int in = 0, out = 0, cheaper = 0;
    for (int round = 0; round < 12; ++round) {
      const size_t n = BatchEvaluator<double>::kBatch;
      values.reserve(*tape);
      signs.reserve(*tape);
      // Clusters of 8 points within 0.02 of each other (half B's inradius about its centroid):
      // the sum reuses the class of a point in no cell for its neighbours.
      std::uniform_real_distribution<double> jitter(-0.01, 0.01);
      double c[3] = {0, 0, 0};
      for (size_t i = 0; i < n; ++i) {
        if (i % 8 == 0) c[0] = u(rng), c[1] = u(rng), c[2] = 0.5 * u(rng);
        const double p[3] = {c[0] + jitter(rng), c[1] + jitter(rng), c[2] + jitter(rng)};
        for (uint32_t k = 0; k < 3; ++k) values.in(k)[i] = signs.in(k)[i] = p[k];
      }
      const double* f = values.eval(*tape, n);
      const double* s = signs.eval(*tape, n);
      for (size_t i = 0; i < n; ++i) {
        if (f[i] == 0) continue;  // on the surface either class is right
        ASSERT_EQ(s[i] >= 0, f[i] >= 0) << f[i] << " vs " << s[i];
        (f[i] >= 0 ? in : out) += 1;
        cheaper += s[i] != f[i];
      }
    }
    EXPECT_GT(in, 20);
    EXPECT_GT(out, 20);
    EXPECT_GT(cheaper, 20);  // the distance was skipped, not computed anyway
  }
}

TEST(MeshConvexSum, IntervalBoundsCertifySignsAndHoldOutsideValues) {
  // The sampler's boxes (DistanceField::bound: f(c) +- the half-diagonal). Inside, the sum's
  // value is a lower bound of the depth, not 1-Lipschitz across cells, so a bound certifies
  // signs only (0 excluded: every point of the box on that side); where the centre is outside
  // it also holds every value (minus the distance, exact, and inside points are at most
  // r - dist(c) deep). Points: corners, centre, random; the sum and the difference; boxes clear
  // of the surface must be decided. (A bound from the gap to the boundary pieces' leaf boxes,
  // with no distance at the centre, measured no faster on bunny ⊕ tetrahedral tool.)
  Expr sum, diff;
  ASSERT_TRUE(lPrismSumAndDifference(sum, diff));
  for (const Expr* e : {&sum, &diff}) {
    TapePtr tape = Tape::compile(*e, 3);
    IntervalEvaluator ie;
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-1.5, 3.5), size(0.005, 0.6), unit(0, 1);
    // Random boxes, then small ones about a point deep inside (L ⊕ C: the corner block; L ⊖ C:
    // the first bar's middle, 0.075 deep).
    const V3 deep = e == &sum ? V3{0.5, 0.5, 0.2} : V3{0.8, 0.5, 0.225};
    std::uniform_real_distribution<double> near(-0.03, 0.03), small(0.003, 0.02);
    int decidedIn = 0, decidedOut = 0, enclosed = 0;
    for (int i = 0; i < 1800; ++i) {
      const bool inner = i >= 1500;
      const V3 c = inner ? V3{deep[0] + near(rng), deep[1] + near(rng), deep[2] + 0.5 * near(rng)}
                         : V3{u(rng), u(rng), 0.5 * u(rng)};
      const double h = inner ? small(rng) : size(rng);
      Interval box[3];
      for (int k = 0; k < 3; ++k) box[k] = Interval(c[size_t(k)] - h, c[size_t(k)] + h * (0.5 + unit(rng)));
      const Interval b = ie.eval(*tape, box);
      ASSERT_LE(b.lo, b.hi);
      V3 mid;
      for (int k = 0; k < 3; ++k) mid[size_t(k)] = 0.5 * (box[k].lo + box[k].hi);
      // The centre outside the sum (of A, or of A^c for the difference, whose values are negated).
      const bool outsideCentre = (e == &sum ? eval(*e, mid) : -eval(*e, mid)) < 0;
      enclosed += outsideCentre;
      for (int j = 0; j < 24; ++j) {
        V3 p;
        for (int k = 0; k < 3; ++k) {
          const double t = j < 8 ? double((j >> k) & 1) : j == 8 ? 0.5 : unit(rng);
          p[size_t(k)] = box[k].lo + t * (box[k].hi - box[k].lo);
        }
        const double f = eval(*e, p);
        if (b.lo > 0) ASSERT_GE(f, 0) << p[0] << " " << p[1] << " " << p[2] << " box " << i;
        if (b.hi < 0) ASSERT_LT(f, 0) << p[0] << " " << p[1] << " " << p[2] << " box " << i;
        if (outsideCentre) {
          ASSERT_GE(f, b.lo - 1e-12) << p[0] << " " << p[1] << " " << p[2] << " box " << i;
          ASSERT_LE(f, b.hi + 1e-12) << p[0] << " " << p[1] << " " << p[2] << " box " << i;
        }
      }
      decidedIn += b.lo > 0;
      decidedOut += b.hi < 0;
    }
    EXPECT_GT(decidedIn, 50) << (e == &sum ? "sum" : "difference");
    EXPECT_GT(decidedOut, 300);
    EXPECT_GT(enclosed, 150);
  }
}

TEST(MeshConvexSum, SamplerReadingSignsOnlyGivesEveryPointTheValuesClass) {
  // The mesher samples with SampleOptions::fieldSignsOnly: the sum's class, not its distance
  // outside. The same leaves, tiles and active voxels as a sample of the values, every stored
  // value of the same class, and outside values that are not the distance (the cheap path ran);
  // the sum and the difference.
  Expr sum, diff;
  ASSERT_TRUE(lPrismSumAndDifference(sum, diff));
  const GridSpec grid = GridSpec::fromBounds({-0.4, -0.4, -0.4}, {2.6, 2.6, 0.8}, 72);
  for (const Expr* e : {&sum, &diff}) {
    TapePtr tape = Tape::compile(*e, 3);
    SampleOptions values, signs;
    values.bandVoxels = signs.bandVoxels = 1;
    signs.fieldSignsOnly = true;
    const SampleResult a = sample(tape, grid, values), b = sample(tape, grid, signs);
    ASSERT_EQ(a.leaves.size(), b.leaves.size());
    ASSERT_EQ(a.tiles.size(), b.tiles.size());
    size_t checked = 0, cheaper = 0;
    for (size_t i = 0; i < a.leaves.size(); ++i) {
      ASSERT_EQ(a.leaves[i].origin, b.leaves[i].origin);
      ASSERT_EQ(a.leaves[i].active, b.leaves[i].active);
      for (size_t v = 0; v < kLeafVoxels; ++v) {
        if (!(a.leaves[i].active[v >> 6] >> (v & 63) & 1)) continue;
        if (a.leaves[i].values[v] == 0) continue;  // on the surface either class is right
        ASSERT_EQ(a.leaves[i].values[v] >= 0, b.leaves[i].values[v] >= 0) << "leaf " << i << " voxel " << v;
        ++checked;
        cheaper += a.leaves[i].values[v] != b.leaves[i].values[v];
      }
    }
    for (size_t i = 0; i < a.tiles.size(); ++i) ASSERT_EQ(a.tiles[i].inside, b.tiles[i].inside);
    EXPECT_GT(checked, 10000u);
    EXPECT_GT(cheaper, 1000u);
  }
}

TEST(MeshConvexSum, ClassesOfClusteredPointsHoldForThinAndThickOperands) {
  // A point in no T ⊕ B takes the class its lattice cell recorded when the cell is smaller than
  // B's inner radius allows, else the translate's own. Clusters of points in one lattice cell
  // (about 0.02 here), for B much thinner than a cell (no shared class allowed) to thicker,
  // each class checked against the union of the two grown blocks, in sign-only batches and in
  // values, the value exact outside.
  const double h = 0.4;
  for (const double w : {0.002, 0.006, 0.012, 0.02, 0.3}) {
    const V3 clo{-w, -0.5 * w, -0.7 * w}, chi{0.8 * w, w, 0.3 * w};
    Expr sum;
    ASSERT_TRUE(minkowski::meshConvexSum(mesh_models::lPrismMesh(h), axisBox(clo, chi), 3, &sum));
    const V3 lo1{clo[0], clo[1], clo[2]}, hi1{2 + chi[0], 1 + chi[1], h + chi[2]};
    const V3 lo2{clo[0], clo[1], clo[2]}, hi2{1 + chi[0], 2 + chi[1], h + chi[2]};
    auto exact = [&](const double* p) {
      const V3 q{p[0], p[1], p[2]};
      return std::max(boxDistance(q, lo1, hi1), boxDistance(q, lo2, hi2));
    };
    TapePtr tape = Tape::compile(sum, 3);
    BatchEvaluator<double> values, signs;
    signs.setFieldSignsOnly(true);
    std::mt19937 rng(17);
    // Centres near the boundary (within 0.05 of a face of the L), points within 0.012 of them.
    std::uniform_real_distribution<double> u(-0.2, 2.2), jitter(-0.012, 0.012), near(-0.05, 0.05);
    int in = 0, out = 0;
    for (int round = 0; round < 40; ++round) {
      const size_t n = BatchEvaluator<double>::kBatch;
      values.reserve(*tape);
      signs.reserve(*tape);
      double c[3] = {0, 0, 0};
      for (size_t i = 0; i < n; ++i) {
        if (i % 16 == 0) {
          c[0] = u(rng), c[1] = u(rng), c[2] = u(rng) * h / 2.2;
          const int face = int(rng() % 3);  // onto x = 1, y = 1 or z = h, then off it a little
          c[face] = (face == 2 ? h : 1.0) + near(rng);
        }
        for (uint32_t k = 0; k < 3; ++k) values.in(k)[i] = signs.in(k)[i] = c[k] + jitter(rng);
      }
      const double* f = values.eval(*tape, n);
      const double* s = signs.eval(*tape, n);
      for (size_t i = 0; i < n; ++i) {
        const double p[3] = {values.in(0)[i], values.in(1)[i], values.in(2)[i]};
        const double e = exact(p);
        if (std::abs(e) < 1e-9) continue;
        ASSERT_EQ(s[i] >= 0, e > 0) << "w " << w << " at " << p[0] << " " << p[1] << " " << p[2];
        ASSERT_EQ(f[i] >= 0, e > 0) << "w " << w << " at " << p[0] << " " << p[1] << " " << p[2];
        if (e < 0) {
          EXPECT_NEAR(f[i], e, 1e-9);
        }
        (e > 0 ? in : out) += 1;
      }
    }
    EXPECT_GT(in, 300) << w;
    EXPECT_GT(out, 300) << w;
  }
}

TEST(MeshConvexSum, TiltedTetrahedronToolKeepsEveryClassNearTheSurface) {
  // L prism ⊕ a tetrahedron in no special position. Each cell T ⊕ B is tested on its facets
  // only, a point first against the plane that separates its lattice cell's centre most, and a
  // point nearer that centre than the first cell's depth there is inside with no plane tested:
  // every class checked against the union of the two blocks ⊕ B, each the intersection of all
  // its candidate supporting planes (the blocks' and B's normals and the edge products),
  // independent of the triangles, at clustered points within 0.03 of the surface.
  const std::array<V3, 4> tv{V3{0.05, -0.07, 0.02}, V3{-0.11, 0.04, -0.06}, V3{0.02, 0.13, 0.09},
                             V3{-0.03, -0.02, 0.17}};
  Expr tet;
  for (int f = 0; f < 4; ++f) {
    const V3 &a = tv[size_t((f + 1) % 4)], &b = tv[size_t((f + 2) % 4)], &c = tv[size_t((f + 3) % 4)];
    V3 n = cross({b[0] - a[0], b[1] - a[1], b[2] - a[2]}, {c[0] - a[0], c[1] - a[1], c[2] - a[2]});
    const V3& d = tv[size_t(f)];
    if (dot(n, d) > dot(n, a)) n = {-n[0], -n[1], -n[2]};  // outward: away from the fourth corner
    const double l = std::sqrt(dot(n, n));
    const Expr plane = (dot(n, a) - (n[0] * X() + n[1] * Y() + n[2] * Z())) / l;
    tet = f == 0 ? plane : min(tet, plane);
  }
  const double h = 0.4;
  Expr sum;
  ASSERT_TRUE(minkowski::meshConvexSum(mesh_models::lPrismMesh(h), tet, 3, &sum));
  // The exact sum: block ⊕ B = {p : u . p <= h_block(u) + h_B(u)} over the candidate normals.
  std::vector<V3> dirs{V3{1, 0, 0}, V3{0, 1, 0}, V3{0, 0, 1}};
  std::vector<V3> normals{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (size_t i = 0; i < 4; ++i)
    for (size_t j = i + 1; j < 4; ++j) {
      const V3 e{tv[j][0] - tv[i][0], tv[j][1] - tv[i][1], tv[j][2] - tv[i][2]};
      for (const V3& d : dirs) {
        const V3 n = cross(d, e);
        normals.push_back(n), normals.push_back({-n[0], -n[1], -n[2]});
      }
      for (size_t k = j + 1; k < 4; ++k) {
        const V3 f{tv[k][0] - tv[i][0], tv[k][1] - tv[i][1], tv[k][2] - tv[i][2]};
        const V3 n = cross(e, f);
        normals.push_back(n), normals.push_back({-n[0], -n[1], -n[2]});
      }
    }
  auto blockSum = [&](const V3& p, const V3& lo, const V3& hi) {
    double depth = INFINITY;
    for (const V3& n : normals) {
      const double l = std::sqrt(dot(n, n));
      double hb = 0, ht = -INFINITY;
      for (int k = 0; k < 3; ++k) hb += n[size_t(k)] * (n[size_t(k)] > 0 ? hi[size_t(k)] : lo[size_t(k)]);
      for (const V3& v : tv) ht = std::max(ht, dot(n, v));
      depth = std::min(depth, (hb + ht - dot(n, p)) / l);
    }
    return depth;  // > 0 inside, < 0 outside (a lower bound of the distance there)
  };
  auto exact = [&](const V3& p) {
    return std::max(blockSum(p, {0, 0, 0}, {2, 1, h}), blockSum(p, {0, 0, 0}, {1, 2, h}));
  };
  TapePtr tape = Tape::compile(sum, 3);
  BatchEvaluator<double> values, signs;
  signs.setFieldSignsOnly(true);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-0.2, 2.2), jitter(-0.03, 0.03);
  int in = 0, out = 0;
  for (int round = 0; round < 60; ++round) {
    const size_t n = BatchEvaluator<double>::kBatch;
    values.reserve(*tape);
    signs.reserve(*tape);
    V3 c{0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
      if (i % 32 == 0) {  // a centre on the sum's surface: bisect between an inside and an outside point
        V3 a{u(rng), u(rng), u(rng) * h / 2.2}, b{u(rng), u(rng), -0.5 + u(rng)};
        if ((exact(a) > 0) == (exact(b) > 0)) a = {0.5, 0.5, 0.5 * h};
        if (exact(a) <= 0) std::swap(a, b);
        if (exact(a) <= 0 || exact(b) > 0) continue;
        for (int k = 0; k < 50; ++k) {
          const V3 m{0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
          (exact(m) > 0 ? a : b) = m;
        }
        c = a;
      }
      for (uint32_t k = 0; k < 3; ++k) values.in(k)[i] = signs.in(k)[i] = c[k] + jitter(rng);
    }
    const double* f = values.eval(*tape, n);
    const double* sg = signs.eval(*tape, n);
    for (size_t i = 0; i < n; ++i) {
      const V3 p{values.in(0)[i], values.in(1)[i], values.in(2)[i]};
      const double e = exact(p);
      if (std::abs(e) < 1e-9) continue;
      ASSERT_EQ(sg[i] >= 0, e > 0) << "class at " << p[0] << " " << p[1] << " " << p[2];
      ASSERT_EQ(f[i] >= 0, e > 0) << "value at " << p[0] << " " << p[1] << " " << p[2];
      (e > 0 ? in : out) += 1;
    }
  }
  EXPECT_GT(in, 2000);
  EXPECT_GT(out, 2000);
}
