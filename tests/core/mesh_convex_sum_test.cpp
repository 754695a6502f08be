// Closed mesh ⊕ / ⊖ convex polytope by the exact construction of mesh_convex_sum.h, against
// closed forms: the zonotope of two boxes in different orientations (membership from its facet
// planes, distance from its support function, volume from its generators), a non-convex L prism
// grown by a box (a union of two boxes: exact signed distance), a tetrahedron eroded by a box (a
// smaller tetrahedron), and meshes of the results closed with the formulas' volumes.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <random>

#include <tbb/task_arena.h>

#include "core/mesh_checks.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/geometry/distance_fields.h"
#include "frep/meshing/mesh.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

using namespace frep;
namespace mc = mesh_checks;

namespace {

using V3 = std::array<double, 3>;
Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }

double eval(const Expr& e, const V3& p) {
  TapePtr t = Tape::compile(e, 3);
  PointEvaluator pe;
  return pe.eval(*t, p.data());
}

double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// The box corner + sum_i t_i g_i (t in [0, 1]^3) written as six planes (a min of affine
// functions, recognised as a convex polytope).
Expr parallelepiped(const V3& corner, const std::array<V3, 3>& g) {
  Expr f;
  bool first = true;
  for (int i = 0; i < 3; ++i) {
    V3 n = cross(g[size_t((i + 1) % 3)], g[size_t((i + 2) % 3)]);
    if (dot(n, g[size_t(i)]) < 0) n = {-n[0], -n[1], -n[2]};
    const double l = std::sqrt(dot(n, n));
    for (double& c : n) c /= l;
    const double lo = dot(n, corner), hi = lo + dot(n, g[size_t(i)]);
    const Expr s = n[0] * X() + n[1] * Y() + n[2] * Z();
    const Expr slab = min(s - lo, hi - s);
    f = first ? slab : min(f, slab);
    first = false;
  }
  return f;
}

Expr axisBox(const V3& lo, const V3& hi) {
  return parallelepiped(lo, {V3{hi[0] - lo[0], 0, 0}, V3{0, hi[1] - lo[1], 0}, V3{0, 0, hi[2] - lo[2]}});
}

// The exact signed distance of the axis box [lo, hi] (positive inside).
double boxDistance(const V3& p, const V3& lo, const V3& hi) {
  double out = 0, in = -INFINITY;
  for (int i = 0; i < 3; ++i) {
    const double c = 0.5 * (lo[size_t(i)] + hi[size_t(i)]), h = 0.5 * (hi[size_t(i)] - lo[size_t(i)]);
    const double q = std::abs(p[size_t(i)] - c) - h;
    out += q > 0 ? q * q : 0;
    in = std::max(in, q);
  }
  return out > 0 ? -std::sqrt(out) : -in;
}

}  // namespace

TEST(MeshConvexSum, ZonotopeOfTwoBoxesHasExactMembershipAndDistance) {
  // A rotated parallelepiped ⊕ an axis box: the zonotope of six generators.
  const double c = std::cos(0.5), s = std::sin(0.5), c2 = std::cos(0.3), s2 = std::sin(0.3);
  const std::array<V3, 3> ga = {V3{0.8 * c, 0.8 * s * c2, 0.8 * s * s2}, V3{-0.5 * s, 0.5 * c * c2, 0.5 * c * s2},
                                V3{0, -0.6 * s2, 0.6 * c2}};
  const V3 ca{-0.4, -0.3, -0.2};
  const V3 blo{-0.1, -0.15, 0.05}, bhi{0.2, 0.1, 0.3};
  const std::array<V3, 3> gb = {V3{bhi[0] - blo[0], 0, 0}, V3{0, bhi[1] - blo[1], 0}, V3{0, 0, bhi[2] - blo[2]}};
  Expr sum;
  ASSERT_TRUE(minkowski::meshConvexSum(parallelepiped(ca, ga), axisBox(blo, bhi), 3, &sum));
  const auto described = minkowski::describeExact(sum);
  ASSERT_EQ(described.size(), 1u);
  EXPECT_NE(described[0].find("exact Minkowski sum convex polytope"), std::string::npos) << described[0];
  // The zonotope: centre + sum of [-1/2, 1/2] g_i; facet normals g_i x g_j, support sum |u.g_i|/2.
  std::vector<V3> gens(ga.begin(), ga.end());
  gens.insert(gens.end(), gb.begin(), gb.end());
  V3 centre{0, 0, 0};
  for (int k = 0; k < 3; ++k) centre[size_t(k)] = ca[size_t(k)] + blo[size_t(k)];
  for (const V3& g : gens)
    for (int k = 0; k < 3; ++k) centre[size_t(k)] += 0.5 * g[size_t(k)];
  auto support = [&](const V3& u) {
    double h = dot(u, centre);
    for (const V3& g : gens) h += 0.5 * std::abs(dot(u, g));
    return h;
  };
  std::vector<V3> normals;
  for (size_t i = 0; i < gens.size(); ++i)
    for (size_t j = i + 1; j < gens.size(); ++j) {
      V3 n = cross(gens[i], gens[j]);
      const double l = std::sqrt(dot(n, n));
      if (l < 1e-12) continue;
      for (double& x : n) x /= l;
      bool known = false;  // three coplanar generators (ga[2], gb[1], gb[2]) give one facet
      for (const V3& k : normals) known = known || dot(k, n) > 1 - 1e-12;
      if (known) continue;
      normals.push_back(n);
      normals.push_back({-n[0], -n[1], -n[2]});
    }
  // Its exact signed distance from the convex polytope of its facet planes (convex_polytope.h).
  Expr planes;
  for (size_t i = 0; i < normals.size(); ++i) {
    const V3& n = normals[i];
    const Expr e = support(n) - (n[0] * X() + n[1] * Y() + n[2] * Z());
    planes = i == 0 ? e : min(planes, e);
  }
  const auto zonotope = minkowski::convexPolytopeOf(planes);
  ASSERT_TRUE(zonotope.has_value());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  int outside = 0, inside = 0;
  for (int i = 0; i < 2000; ++i) {
    const V3 p{u(rng), u(rng), u(rng)};
    const double exact = eval(zonotope->field, p), f = eval(sum, p);
    if (std::abs(exact) < 1e-9) continue;
    ASSERT_EQ(f >= 0, exact > 0) << p[0] << " " << p[1] << " " << p[2];
    if (exact > 0) {  // inside: a positive lower bound of the depth
      ++inside;
      EXPECT_LE(f, exact + 1e-9);
      EXPECT_GT(f, 0);
    } else {
      ++outside;
      EXPECT_NEAR(f, exact, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(outside, 1000);
  EXPECT_GT(inside, 50);
  // Its mesh: closed, the zonotope's volume sum over triples of |det(g_i, g_j, g_k)|.
  double volume = 0;
  for (size_t i = 0; i < 6; ++i)
    for (size_t j = i + 1; j < 6; ++j)
      for (size_t k = j + 1; k < 6; ++k) volume += std::abs(dot(gens[i], cross(gens[j], gens[k])));
  Mesh m = meshGrid(Tape::compile(sum, 3), mesh_models::cubeGrid(1.6, 96), {}, 32);
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), volume, 0.003 * volume);
}

TEST(MeshConvexSum, NonConvexMeshGrownByABoxIsTheUnionOfTheGrownBlocks) {
  // L ⊕ C = ([0,2]x[0,1]x[0,h] ⊕ C) ∪ ([0,1]x[0,2]x[0,h] ⊕ C): outside, the distance to the
  // nearer grown block exactly; the sign everywhere.
  const double h = 0.4;
  const V3 clo{-0.1, -0.2, -0.15}, chi{0.3, 0.05, 0.1};
  Expr sum;
  ASSERT_TRUE(minkowski::meshConvexSum(axisBox(clo, chi), mesh_models::lPrismMesh(h), 3, &sum));  // either order
  const V3 lo1{clo[0], clo[1], clo[2]}, hi1{2 + chi[0], 1 + chi[1], h + chi[2]};
  const V3 lo2{clo[0], clo[1], clo[2]}, hi2{1 + chi[0], 2 + chi[1], h + chi[2]};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.8, 2.8);
  int outside = 0;
  for (int i = 0; i < 3000; ++i) {
    const V3 p{u(rng), u(rng), 0.5 * u(rng)};
    const double exact = std::max(boxDistance(p, lo1, hi1), boxDistance(p, lo2, hi2));
    const double f = eval(sum, p);
    if (std::abs(exact) < 1e-9) continue;
    ASSERT_EQ(f >= 0, exact > 0) << p[0] << " " << p[1] << " " << p[2];
    if (exact < 0) {
      ++outside;
      EXPECT_NEAR(f, exact, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    } else {
      EXPECT_LE(f, exact + 1e-9);  // inside: a lower bound of the depth
    }
  }
  EXPECT_GT(outside, 1000);
  const double volume = (hi1[0] - lo1[0]) * (hi1[1] - lo1[1]) * (hi1[2] - lo1[2]) +
                        (hi2[0] - lo2[0]) * (hi2[1] - lo2[1]) * (hi2[2] - lo2[2]) -
                        (hi2[0] - lo2[0]) * (hi1[1] - lo1[1]) * (hi1[2] - lo1[2]);
  Mesh m = meshGrid(Tape::compile(sum, 3), GridSpec::fromBounds({-0.4, -0.4, -0.4}, {2.6, 2.6, 0.8}, 97), {}, 32);
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), 2);
  EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), volume, 0.003 * volume);
}

// The same L written as a block minus a block (a union of polytopes, convex_polytope.h) is its
// own cover: a box ⊕ it is the union of the grown blocks, a big box ⊖ it the intersection of
// the shrunk boxes (A ⊖ (K1 ∪ K2) = (A ⊖ K1) ∩ (A ⊖ K2)), each exact on its side.
TEST(MeshConvexSum, ToolWrittenAsABlockDifferenceIsCoveredByItsBoxes) {
  const double h = 0.4;
  const Expr ell = min(axisBox({0, 0, 0}, {2, 2, h}), -axisBox({1, 1, -1}, {3, 3, 1}));
  const V3 clo{-0.1, -0.2, -0.15}, chi{0.3, 0.05, 0.1};
  Expr sum;
  ASSERT_TRUE(minkowski::meshConvexSum(axisBox(clo, chi), ell, 3, &sum));
  const auto described = minkowski::describeExact(sum);
  ASSERT_FALSE(described.empty());
  EXPECT_NE(described[0].find("union of 2 convex pieces"), std::string::npos) << described[0];
  const V3 lo1{clo[0], clo[1], clo[2]}, hi1{2 + chi[0], 1 + chi[1], h + chi[2]};
  const V3 lo2{clo[0], clo[1], clo[2]}, hi2{1 + chi[0], 2 + chi[1], h + chi[2]};
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> u(-0.8, 2.8);
  int outside = 0;
  for (int i = 0; i < 2000; ++i) {
    const V3 p{u(rng), u(rng), 0.5 * u(rng)};
    const double exact = std::max(boxDistance(p, lo1, hi1), boxDistance(p, lo2, hi2)), f = eval(sum, p);
    if (std::abs(exact) < 1e-9) continue;
    ASSERT_EQ(f >= 0, exact > 0) << p[0] << " " << p[1] << " " << p[2];
    if (exact < 0) {
      ++outside;
      EXPECT_NEAR(f, exact, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(outside, 1000);
  const V3 alo{-1, -1, -1}, ahi{3, 3, 1.5};
  Expr diff;
  ASSERT_TRUE(minkowski::meshConvexDifference(axisBox(alo, ahi), ell, 3, &diff));
  // A ⊖ [0,1]x[0,2]x[0,h] and A ⊖ [0,2]x[0,1]x[0,h]: [alo, ahi - hi_k].
  const V3 s1{ahi[0] - 1, ahi[1] - 2, ahi[2] - h}, s2{ahi[0] - 2, ahi[1] - 1, ahi[2] - h};
  int inside = 0;
  for (int i = 0; i < 2000; ++i) {
    const V3 p{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 1};
    const double exact = std::min(boxDistance(p, alo, s1), boxDistance(p, alo, s2)), f = eval(diff, p);
    if (std::abs(exact) < 1e-9) continue;
    ASSERT_EQ(f >= 0, exact > 0) << p[0] << " " << p[1] << " " << p[2];
    if (exact > 0) {
      ++inside;
      EXPECT_NEAR(f, exact, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(inside, 300);
  // Two boxes apart (a bar minus a slab across it): one translate A + b0 cannot stand for both,
  // so this form is refused (the search takes it), never answered wrong: (1.35, 0.5, 0.5) lies
  // in A ⊕ B for A = [0, 1]^3 (a point of A deep inside, plus one of the second box), but
  // neither in A plus a point of the first box nor near A's boundary plus either box.
  const Expr apart = min(axisBox({0, 0, 0}, {0.6, 0.1, 0.1}), max(0.1 - X(), X() - 0.5));
  const auto two = minkowski::polytopeUnionOf(apart);
  ASSERT_TRUE(two.has_value());
  EXPECT_EQ(two->pieces, 2u);
  EXPECT_FALSE(two->connected());
  EXPECT_TRUE(minkowski::polytopeUnionOf(ell)->connected());
  Expr wrong;
  if (minkowski::meshConvexSum(axisBox({0, 0, 0}, {1, 1, 1}), apart, 3, &wrong)) {
    EXPECT_GE(eval(wrong, {1.35, 0.5, 0.5}), 0);
  }
}

TEST(MeshConvexSum, TetrahedronErodedByABoxIsTheShrunkTetrahedron) {
  // T = {x, y, z >= -0.3, x + y + z <= 0.6}; T ⊖ C = {x : x + C ⊆ T} moves each plane by C's
  // support: x >= -0.3 - min_C x, ..., x + y + z <= 0.6 - max_C (x + y + z).
  const Expr tet = min(min(X() + 0.3, Y() + 0.3), min(Z() + 0.3, (0.6 - X() - Y() - Z()) / std::sqrt(3.0)));
  const V3 clo{-0.2, -0.1, 0.0}, chi{0.2, 0.2, 0.2};
  Expr diff;
  ASSERT_TRUE(minkowski::meshConvexDifference(tet, axisBox(clo, chi), 3, &diff));
  const double a = -0.3 - clo[0], b = -0.3 - clo[1], c = -0.3 - clo[2], d = 0.6 - (chi[0] + chi[1] + chi[2]);
  const auto shrunk = minkowski::convexPolytopeOf(min(min(X() - a, Y() - b), min(Z() - c, d - X() - Y() - Z())));
  ASSERT_TRUE(shrunk.has_value());
  auto exact = [&](const V3& p) { return eval(shrunk->field, p); };
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.5, 0.6);
  int inside = 0;
  for (int i = 0; i < 3000; ++i) {
    const V3 p{u(rng), u(rng), u(rng)};
    const double e = exact(p), f = eval(diff, p);
    if (std::abs(e) < 1e-9) continue;
    ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
    if (e > 0) {
      ++inside;
      EXPECT_NEAR(f, e, 1e-9);
    } else {
      EXPECT_GE(f, e - 1e-9);  // outside: -f is at most the distance (a lower bound of it)
      EXPECT_LT(f, 0);
    }
  }
  EXPECT_GT(inside, 20);
  // The mirrored operand is not commuted: B ⊖ A is not A ⊖ B.
  Expr none;
  EXPECT_FALSE(minkowski::meshConvexDifference(min(X(), Y()), axisBox(clo, chi), 3, &none));
}

// L ⊕ C and L ⊖ C for the L prism of height 0.4 and a small box C (the tests of classes,
// bounds and signs-only sampling).
static bool lPrismSumAndDifference(Expr& sum, Expr& diff) {
  const V3 clo{-0.1, -0.2, -0.15}, chi{0.3, 0.05, 0.1};
  return minkowski::meshConvexSum(axisBox(clo, chi), mesh_models::lPrismMesh(0.4), 3, &sum) &&
         minkowski::meshConvexDifference(mesh_models::lPrismMesh(0.4), axisBox(clo, chi), 3, &diff);
}

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

// An L prism s ([0,2]x[0,1] ∪ [0,1]x[0,2]) x [0, h] + shift as a closed mesh (lPrism's faces).
Expr lPrismAt(double s, double h, const V3& shift) {
  const double L[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<double> xyz;
  for (double z : {0.0, h})
    for (const auto& p : L) xyz.insert(xyz.end(), {s * p[0] + shift[0], s * p[1] + shift[1], z + shift[2]});
  const uint32_t cap[4][3] = {{3, 4, 5}, {3, 5, 0}, {3, 0, 1}, {3, 1, 2}};
  std::vector<uint32_t> tris;
  for (const auto& t : cap) {
    tris.insert(tris.end(), {t[0] + 6, t[1] + 6, t[2] + 6});
    tris.insert(tris.end(), {t[0], t[2], t[1]});
  }
  for (uint32_t i = 0; i < 6; ++i) {
    const uint32_t j = (i + 1) % 6;
    tris.insert(tris.end(), {i, j, j + 6});
    tris.insert(tris.end(), {i, j + 6, i + 6});
  }
  return fieldExpr(std::make_shared<MeshField>(xyz, tris, "L tool"), X(), Y(), Z());
}

TEST(MeshConvexSum, NonConvexToolIsCutIntoConvexPieces) {
  // L ⊕ L' with both operands non-convex: the tool is covered by convex pieces (two bars),
  // and the sum is the union of the four block sums A_i ⊕ B_j (a block ⊕ a block is the block
  // of summed corners): exact outside, the sign everywhere. Then a block eroded by the L tool,
  // (C ⊖ B_1) ∩ (C ⊖ B_2): exact inside.
  const double h = 0.4, s = 0.1, hb = 0.05;
  const V3 shift{-0.07, -0.04, -0.02};
  // Either operand as the one cut: the big L's pieces against the small L (where every piece
  // shows), then the small L's.
  const std::array<std::array<V3, 2>, 2> A{{{V3{0, 0, 0}, V3{2, 1, h}}, {V3{0, 0, 0}, V3{1, 2, h}}}};
  const std::array<std::array<V3, 2>, 2> B{
      {{V3{shift[0], shift[1], shift[2]}, V3{2 * s + shift[0], s + shift[1], hb + shift[2]}},
       {V3{shift[0], shift[1], shift[2]}, V3{s + shift[0], 2 * s + shift[1], hb + shift[2]}}}};
  std::mt19937 rng(23);
  for (const bool bigCut : {true, false}) {
    Expr sum;
    ASSERT_TRUE(bigCut ? minkowski::meshConvexSum(lPrismAt(s, hb, shift), mesh_models::lPrismMesh(h), 3, &sum)
                       : minkowski::meshConvexSum(mesh_models::lPrismMesh(h), lPrismAt(s, hb, shift), 3, &sum));
    // The cut L is covered by its two overlapping bars (convex_cover.h), not ten pyramids.
    const auto term = minkowski::lookupExact(sum);
    ASSERT_TRUE(term);
    EXPECT_NE(term->operand.find(" as 2 convex pieces"), std::string::npos) << term->operand;
    auto unionOfSums = [&](const V3& p) {
      double f = -INFINITY;
      for (const auto& a : A)
        for (const auto& b : B) {
          const V3 lo{a[0][0] + b[0][0], a[0][1] + b[0][1], a[0][2] + b[0][2]};
          const V3 hi{a[1][0] + b[1][0], a[1][1] + b[1][1], a[1][2] + b[1][2]};
          f = std::max(f, boxDistance(p, lo, hi));
        }
      return f;
    };
    std::uniform_real_distribution<double> u(-0.4, 2.4), uz(-0.3, 0.7);
    int in = 0, out = 0;
    for (int i = 0; i < 3000; ++i) {
      const V3 p{u(rng), u(rng), uz(rng)};
      const double e = unionOfSums(p), f = eval(sum, p);
      if (std::abs(e) < 1e-9) continue;
      ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
      if (e < 0) {
        EXPECT_NEAR(f, e, 1e-9) << p[0] << " " << p[1] << " " << p[2];
      }
      (e > 0 ? in : out) += 1;
    }
    EXPECT_GT(in, 300);
    EXPECT_GT(out, 300);
  }

  const V3 clo{-1, -1, -1}, chi{3, 2.5, 1.4};
  Expr diff;
  ASSERT_TRUE(minkowski::meshConvexDifference(axisBox(clo, chi), lPrismAt(s, hb, shift), 3, &diff));
  auto eroded = [&](const V3& p) {
    // C ⊖ B_j is the block [clo - lo_j, chi - hi_j]; the erosion is their intersection.
    V3 lo{-INFINITY, -INFINITY, -INFINITY}, hi{INFINITY, INFINITY, INFINITY};
    for (const auto& b : B)
      for (int k = 0; k < 3; ++k)
        lo[size_t(k)] = std::max(lo[size_t(k)], clo[size_t(k)] - b[0][size_t(k)]),
        hi[size_t(k)] = std::min(hi[size_t(k)], chi[size_t(k)] - b[1][size_t(k)]);
    return boxDistance(p, lo, hi);
  };
  std::uniform_real_distribution<double> w(-1.3, 3.3);
  int inside = 0;
  for (int i = 0; i < 3000; ++i) {
    const V3 p{w(rng), w(rng), 0.6 * w(rng)};
    const double e = eroded(p), f = eval(diff, p);
    if (std::abs(e) < 1e-9) continue;
    ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
    if (e > 0) {
      ++inside;
      EXPECT_NEAR(f, e, 1e-9);
    }
  }
  EXPECT_GT(inside, 300);
}

// The boundary pieces' pruning tests the triangles in parallel; each test is a function of its
// triangle alone, so the sum built on one thread and on all of them is the same field: the
// same count of pieces and the same values (a fine torus, so that the pruning runs in several
// chunks). The second build takes the torus with its triangles in reverse order: another mesh
// object of the same solid, so it is built anew (the same mesh would share the first build's
// node, which the registry of exact terms keeps alive); its sums of normals then round in
// another order, so values agree to 1e-12, not bit for bit (a piece wrongly dropped moves the
// distance by far more, one wrongly kept changes the count).
TEST(MeshConvexSum, PruningOnOneThreadOrManyBuildsTheSameSum) {
  const mesh_models::TorusSoup soup = mesh_models::torusSoup(0.8, 0.3, 64, 32);
  std::vector<uint32_t> reversed;
  for (size_t t = soup.tris.size(); t >= 3; t -= 3) reversed.insert(reversed.end(), &soup.tris[t - 3], &soup.tris[t]);
  auto sum = [&](const std::vector<uint32_t>& tris, Expr* out) {
    const Expr torus = fieldExpr(std::make_shared<MeshField>(soup.xyz, tris, "torus"), X(), Y(), Z());
    return minkowski::meshConvexSum(torus, axisBox({-0.05, -0.03, -0.02}, {0.05, 0.05, 0.05}), 3, out);
  };
  Expr one, many;
  tbb::task_arena single(1);
  bool ok = false;
  single.execute([&] { ok = sum(soup.tris, &one); });
  ASSERT_TRUE(ok);
  ASSERT_TRUE(sum(reversed, &many));
  ASSERT_FALSE(one.same(many));  // two builds
  const auto termOne = minkowski::lookupExact(one), termMany = minkowski::lookupExact(many);
  ASSERT_TRUE(termOne && termMany);
  EXPECT_EQ(termOne->operand, termMany->operand);  // with the count of pieces kept
  EXPECT_NE(termOne->operand.find("boundary pieces"), std::string::npos) << termOne->operand;
  const TapePtr t1 = Tape::compile(one, 3), t2 = Tape::compile(many, 3);
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  PointEvaluator pe;
  for (int i = 0; i < 2000; ++i) {
    const V3 p{u(rng), u(rng), 0.4 * u(rng)};
    const double a = pe.eval(*t1, p.data()), b = pe.eval(*t2, p.data());
    ASSERT_NEAR(a, b, 1e-12) << i;
  }
}
