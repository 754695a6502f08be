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
#include "core/mesh_convex_sum_shapes.h"
#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/geometry/distance_fields.h"
#include "frep/meshing/mesh.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/primitives/ops.h"

using namespace frep;
namespace mc = mesh_checks;

using namespace frep::mesh_convex_sum_shapes;

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
