// Small closed meshes read as unions of convex polytopes (convex_polytope.h,
// polytopeUnionOfMesh): the mesh distance's set everywhere and its exact value outside, and the
// sum with a ball taking the offset path with the closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/distance_offset.h"
#include "frep/minkowski_algebra/registry.h"

using namespace frep;
using mesh_models::X;
using mesh_models::Y;
using mesh_models::Z;

namespace {

// The box [lo, hi] as a closed mesh of 12 triangles, outward.
Expr boxMesh(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  std::vector<double> xyz;
  for (int k = 0; k < 8; ++k)
    xyz.insert(xyz.end(), {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]});
  const std::vector<uint32_t> tris = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                      2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  auto m = std::make_shared<MeshField>(xyz, tris, "box mesh");
  EXPECT_TRUE(m->check().closed());
  return fieldExpr(m, X(), Y(), Z());
}

// The field against the mesh's own distance at random points: equal outside, the same sign
// inside (there the union's max of the pieces' depths is a lower bound).
void expectSameOutside(const Expr& union_, const Expr& mesh, const std::array<double, 3>& c, double half) {
  TapePtr a = Tape::compile(union_, 3), b = Tape::compile(mesh, 3);
  PointEvaluator pe;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-half, half);
  int outside = 0, inside = 0;
  for (int i = 0; i < 6000; ++i) {
    const double p[3] = {c[0] + u(rng), c[1] + u(rng), c[2] + u(rng)};
    const double fa = pe.eval(*a, p), fb = pe.eval(*b, p);
    if (fb < 0) {
      ++outside;
      EXPECT_NEAR(fa, fb, 1e-12) << p[0] << " " << p[1] << " " << p[2];
    } else if (fb > 1e-12) {
      ++inside;
      EXPECT_GT(fa, 0) << p[0] << " " << p[1] << " " << p[2];
      EXPECT_LE(fa, fb + 1e-12);
    }
  }
  EXPECT_GT(outside, 100);
  EXPECT_GT(inside, 100);
}

}  // namespace

TEST(MeshPolytopes, ABoxMeshIsOneBox) {
  const Expr mesh = boxMesh({-0.5, -0.3, -0.2}, {0.4, 0.3, 0.6});
  std::string what;
  auto u = minkowski::polytopeUnionOfMesh(mesh, &what);
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(u->pieces, 1u);
  EXPECT_EQ(u->boxes, 1u);
  EXPECT_EQ(what.find("box mesh"), 0u) << what;
  expectSameOutside(u->field, mesh, {0, 0, 0}, 1.0);
}

TEST(MeshPolytopes, AnLPrismMeshIsTwoOverlappingBoxes) {
  const Expr mesh = mesh_models::lPrismMesh(0.5);
  std::string what;
  auto u = minkowski::polytopeUnionOfMesh(mesh, &what);
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(u->pieces, 2u);
  EXPECT_EQ(u->boxes, 2u);
  expectSameOutside(u->field, mesh, {1, 1, 0.25}, 1.5);
}

TEST(MeshPolytopes, CurvedOrLargeMeshesAreNotRead) {
  // A polytope written as planes is not a mesh operand; a 320-triangle sphere mesh is too large.
  EXPECT_FALSE(minkowski::polytopeUnionOfMesh(mesh_models::blockAt(0, 0, 0, 1, 1, 1), nullptr).has_value());
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  const int n = 16, m = 11;  // a UV sphere: n longitudes, m - 1 rings, two poles
  xyz.insert(xyz.end(), {0, 0, 1});
  for (int i = 1; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      const double th = mesh_models::kPi * i / m, ph = 2 * mesh_models::kPi * j / n;
      xyz.insert(xyz.end(), {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  xyz.insert(xyz.end(), {0, 0, -1});
  const uint32_t south = uint32_t(1 + n * (m - 1));
  auto at = [&](int i, int j) { return uint32_t(1 + (i - 1) * n + (j % n)); };
  for (int j = 0; j < n; ++j) {
    tris.insert(tris.end(), {0, at(1, j), at(1, j + 1)});
    tris.insert(tris.end(), {south, at(m - 1, j + 1), at(m - 1, j)});
    for (int i = 1; i + 1 < m; ++i) {
      tris.insert(tris.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      tris.insert(tris.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  auto sphere = std::make_shared<MeshField>(xyz, tris, "sphere mesh");
  ASSERT_TRUE(sphere->check().closed());
  ASSERT_GT(sphere->numTriangles(), 256u);
  std::string what;
  EXPECT_FALSE(minkowski::polytopeUnionOfMesh(fieldExpr(sphere, X(), Y(), Z()), &what).has_value());
}

TEST(MeshPolytopes, LPrismMeshPlusBallIsTheOffsetOfTheClosedForms) {
  const Expr mesh = mesh_models::lPrismMesh(0.5);
  const double r = 0.3;
  const Expr ball = r * r - X() * X() - Y() * Y() - Z() * Z();
  minkowski::Shape s;
  s.kind = minkowski::ShapeKind::Sphere;
  s.size[0] = r;
  minkowski::ExactTerm t;
  t.sum = minkowski::sumOf(s);
  t.pieces = 1;
  minkowski::registerExact(ball, t);
  Expr sum;
  ASSERT_TRUE(minkowski::distanceBallSum(mesh, ball, 3, &sum));
  const std::vector<std::string> lines = minkowski::describeExact(sum);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("L prism (20 triangles) as a union of 2 convex pieces (2 of them boxes)"), std::string::npos)
      << lines[0];
  // No mesh node left: the sum is the closed forms' offset, equal to the mesh distance + r outside.
  bool meshNode = false;
  forEachNode(sum, [&](const Node& n) { meshNode = meshNode || n.op == Op::Field; });
  EXPECT_FALSE(meshNode);
  TapePtr a = Tape::compile(sum, 3), b = Tape::compile(mesh, 3);
  PointEvaluator pe;
  for (const std::array<double, 3>& p : std::vector<std::array<double, 3>>{
           {1.5, 1.5, 0.25}, {2.2, 0.5, 0.7}, {-0.1, -0.2, -0.1}, {1.2, 1.1, 0.25}, {0.5, 2.25, 0.25}})
    EXPECT_NEAR(pe.eval(*a, p.data()), pe.eval(*b, p.data()) + r, 1e-12) << p[0] << " " << p[1] << " " << p[2];
}
