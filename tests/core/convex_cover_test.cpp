// Covers of non-convex tools by overlapping convex pieces (convex_cover.h), against exact
// answers: polyomino prisms (L, T, U, plus) come out as their fewest boxes, each piece lies in
// the tool and their union is the tool at every sample (membership from the unit squares), the
// containment test rejects pieces poking out (across the L's notch, the notch itself, the U's
// hull), and sums and differences with a non-star-shaped U tool are unions and intersections
// of block sums.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_cover.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/minkowski_algebra/star_pieces.h"
#include "frep/primitives/ops.h"

using namespace frep;
using minkowski::PieceMesh;

namespace {

using Cells = std::vector<std::array<int, 2>>;
using Tris = std::vector<std::array<uint32_t, 3>>;

struct Tool {
  std::vector<Vec3> v;
  Tris t;
};

// The prism of height h over unit squares of the grid, a closed outward mesh on the grid's
// points (coplanar cap triangles, walls split at every grid point).
Tool polyominoPrism(const Cells& cells, double h) {
  Tool m;
  std::map<std::array<int, 3>, uint32_t> index;
  auto at = [&](int x, int y, int z) {
    auto [it, fresh] = index.insert({{x, y, z}, uint32_t(m.v.size())});
    if (fresh) m.v.push_back({double(x), double(y), z * h});
    return it->second;
  };
  auto quad = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    m.t.push_back({a, b, c});
    m.t.push_back({a, c, d});
  };
  const std::set<std::array<int, 2>> has(cells.begin(), cells.end());
  for (const auto& [x, y] : cells) {
    quad(at(x, y, 1), at(x + 1, y, 1), at(x + 1, y + 1, 1), at(x, y + 1, 1));
    quad(at(x, y, 0), at(x, y + 1, 0), at(x + 1, y + 1, 0), at(x + 1, y, 0));
    if (!has.count({x, y - 1})) quad(at(x, y, 0), at(x + 1, y, 0), at(x + 1, y, 1), at(x, y, 1));
    if (!has.count({x + 1, y})) quad(at(x + 1, y, 0), at(x + 1, y + 1, 0), at(x + 1, y + 1, 1), at(x + 1, y, 1));
    if (!has.count({x, y + 1})) quad(at(x + 1, y + 1, 0), at(x, y + 1, 0), at(x, y + 1, 1), at(x + 1, y + 1, 1));
    if (!has.count({x - 1, y})) quad(at(x, y + 1, 0), at(x, y, 0), at(x, y, 1), at(x, y + 1, 1));
  }
  return m;
}

bool inCells(const Cells& cells, double h, const Vec3& p) {
  if (p[2] < 0 || p[2] > h) return false;
  for (const auto& [x, y] : cells)
    if (p[0] >= x && p[0] <= x + 1 && p[1] >= y && p[1] <= y + 1) return true;
  return false;
}

bool inPiece(const PieceMesh& k, const Vec3& p, double tol) {
  for (const auto& f : k.t) {
    const Vec3 n = vec3::cross(vec3::sub(k.v[f[1]], k.v[f[0]]), vec3::sub(k.v[f[2]], k.v[f[0]]));
    if (vec3::dot(n, vec3::sub(p, k.v[f[0]])) > tol * vec3::norm(n)) return false;
  }
  return true;
}

double volumeOf(const PieceMesh& m) {
  double vol = 0;
  for (const auto& f : m.t) vol += vec3::dot(m.v[f[0]], vec3::cross(m.v[f[1]], m.v[f[2]])) / 6;
  return vol;
}

PieceMesh boxMesh(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i) pts.push_back({i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]});
  return *minkowski::convexHullMesh(pts, 1e-12);
}

const Cells kL{{0, 0}, {1, 0}, {0, 1}};
const Cells kT{{0, 1}, {1, 1}, {2, 1}, {1, 0}};
const Cells kU{{0, 0}, {1, 0}, {2, 0}, {0, 1}, {2, 1}};
const Cells kPlus{{1, 0}, {0, 1}, {1, 1}, {2, 1}, {1, 2}};

}  // namespace

TEST(ConvexCover, PolyominoPrismsAreCoveredByTheirFewestBoxes) {
  // The fewest convex pieces: two bars for L, T and plus, three for U and five for a comb (not
  // star-shaped: inner walls face each other). Every piece is a box of the grid inside the
  // tool, and a point lies in the tool iff it lies in some piece (samples off the grid lines).
  const double h = 0.4;
  Cells comb;  // a bar with four teeth of length 3: not star-shaped, five pieces
  for (int x = 0; x < 8; ++x) comb.push_back({x, 0});
  for (int x = 0; x < 8; x += 2)
    for (int y = 1; y <= 3; ++y) comb.push_back({x, y});
  const std::vector<std::pair<Cells, size_t>> shapes{{kL, 2}, {kT, 2}, {kU, 3}, {kPlus, 2}, {comb, 5}};
  for (const auto& [cells, count] : shapes) {
    const Tool tool = polyominoPrism(cells, h);
    auto cover = minkowski::convexCover(tool.v, tool.t, 64);
    ASSERT_TRUE(cover) << cells.size();
    EXPECT_EQ(cover->size(), count) << cells.size();
    double area = 0;
    for (const PieceMesh& k : *cover) {
      Vec3 lo = k.v[0], hi = k.v[0];
      for (const Vec3& p : k.v) {
        EXPECT_TRUE(inCells(cells, h, p)) << p[0] << " " << p[1] << " " << p[2];
        for (size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
      }
      // A box of the grid: its volume is its bounding box's, its corners on grid points.
      EXPECT_NEAR(volumeOf(k), (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]), 1e-12);
      for (size_t a = 0; a < 2; ++a) {
        EXPECT_NEAR(lo[a], std::round(lo[a]), 1e-12);
        EXPECT_NEAR(hi[a], std::round(hi[a]), 1e-12);
      }
      EXPECT_NEAR(lo[2], 0, 1e-12);
      EXPECT_NEAR(hi[2], h, 1e-12);
      area += (hi[0] - lo[0]) * (hi[1] - lo[1]);
    }
    EXPECT_GE(area, double(cells.size()));  // overlapping pieces count twice
    for (double x = -0.2371; x < 8.2; x += 0.0931)
      for (double y = -0.2113; y < 4.2; y += 0.0877)
        for (double z : {-0.05, 0.013, 0.2, 0.39, 0.45}) {
          const Vec3 p{x, y, z};
          bool any = false;
          for (const PieceMesh& k : *cover) any = any || inPiece(k, p, 0);
          ASSERT_EQ(any, inCells(cells, h, p)) << x << " " << y << " " << z;
        }
    // Fewer pieces than the pyramids from a kernel point, where there is one.
    auto star = minkowski::starConvexPieces(tool.v, tool.t, 1e-6, 64);
    if (cells == kU || cells == comb) {
      EXPECT_FALSE(star);
    } else {
      ASSERT_TRUE(star);
      EXPECT_LT(cover->size(), star->size());
    }
  }
  // The L is its two bars, overlapping in the corner square.
  const Tool l = polyominoPrism(kL, h);
  auto cover = minkowski::convexCover(l.v, l.t, 64);
  ASSERT_TRUE(cover && cover->size() == 2);
  std::set<std::array<double, 2>> extents;
  for (const PieceMesh& k : *cover) {
    double hx = 0, hy = 0;
    for (const Vec3& p : k.v) hx = std::max(hx, p[0]), hy = std::max(hy, p[1]);
    extents.insert({hx, hy});
  }
  EXPECT_EQ(extents, (std::set<std::array<double, 2>>{{2, 1}, {1, 2}}));
}

TEST(ConvexCover, TurnedLPrismIsTwoOverlappingBars) {
  // The L turned about two axes and scaled: still two pieces of volume 2 h s^3 (the bars),
  // each inside the turned tool, and the tool's volume 3 h s^3 is covered (inclusion-exclusion:
  // the bars overlap in one unit square).
  const double h = 0.7, s = 0.05, a = 0.4, b = 0.9;
  Tool tool = polyominoPrism(kL, h);
  auto turn = [&](const Vec3& p) {
    const Vec3 q{std::cos(a) * p[0] - std::sin(a) * p[1], std::sin(a) * p[0] + std::cos(a) * p[1], p[2]};
    return Vec3{s * q[0] + 0.3, s * (std::cos(b) * q[1] - std::sin(b) * q[2]) - 0.2,
                s * (std::sin(b) * q[1] + std::cos(b) * q[2])};
  };
  for (Vec3& p : tool.v) p = turn(p);
  auto cover = minkowski::convexCover(tool.v, tool.t, 64);
  ASSERT_TRUE(cover);
  ASSERT_EQ(cover->size(), 2u);
  for (const PieceMesh& k : *cover) {
    EXPECT_NEAR(volumeOf(k), 2 * h * s * s * s, 1e-12);
    EXPECT_TRUE(minkowski::convexInsideMesh(k, tool.v, tool.t, 1e-9));
  }
}

TEST(ConvexCover, ContainmentRejectsPiecesPokingOutOfTheTool) {
  const double h = 0.4;
  const Tool l = polyominoPrism(kL, h);
  auto inside = [&](const PieceMesh& k) { return minkowski::convexInsideMesh(k, l.v, l.t, 1e-9); };
  EXPECT_TRUE(inside(boxMesh({0, 0, 0}, {2, 1, h})));
  EXPECT_TRUE(inside(boxMesh({0.1, 0.2, 0.1}, {0.9, 1.8, 0.3})));
  EXPECT_FALSE(inside(boxMesh({0, 0, 0}, {2, 1 + 1e-6, h})));       // through the notch's wall
  EXPECT_FALSE(inside(boxMesh({0, 0, -1e-6}, {1, 1, h})));          // through the floor
  EXPECT_FALSE(inside(boxMesh({1, 1, 0}, {2, 2, h})));              // the notch: corners on the tool
  EXPECT_FALSE(inside(boxMesh({1.2, 1.2, 0.1}, {1.8, 1.8, 0.3})));  // out, no tool face near
  EXPECT_FALSE(inside(boxMesh({0, 0, 0}, {2, 2, h})));              // the hull of the L
  // The pyramids from a kernel point lie in the tool; the hull of the two over the far ends of
  // the arms reaches across the notch.
  auto star = minkowski::starConvexPieces(l.v, l.t, 1e-6, 64);
  ASSERT_TRUE(star);
  const PieceMesh *endX = nullptr, *endY = nullptr;
  for (const PieceMesh& k : *star) {
    EXPECT_TRUE(inside(k));
    size_t atX = 0, atY = 0;
    for (const Vec3& p : k.v) atX += p[0] == 2, atY += p[1] == 2;
    if (atX >= 3) endX = &k;
    if (atY >= 3) endY = &k;
  }
  ASSERT_TRUE(endX && endY);
  std::vector<Vec3> both = endX->v;
  both.insert(both.end(), endY->v.begin(), endY->v.end());
  auto across = minkowski::convexHullMesh(both, 1e-12);
  ASSERT_TRUE(across);
  EXPECT_FALSE(inside(*across));
  // The U's hull: every corner on the tool, the gap between the arms inside it.
  const Tool u = polyominoPrism(kU, h);
  EXPECT_FALSE(minkowski::convexInsideMesh(*minkowski::convexHullMesh(u.v, 1e-12), u.v, u.t, 1e-9));
}

TEST(ConvexCover, ConvexOrDisconnectedToolsAreLeftAlone) {
  const Tool box = polyominoPrism({{0, 0}, {1, 0}}, 0.5);
  EXPECT_FALSE(minkowski::convexCover(box.v, box.t, 64));  // convexOf's case
  const Tool apart = polyominoPrism({{0, 0}, {2, 0}}, 0.5);
  EXPECT_FALSE(minkowski::convexCover(apart.v, apart.t, 64));  // A ⊕ B needs B connected
}

TEST(ConvexCover, NonStarShapedUToolSumsAreUnionsOfBlockSums) {
  // L ⊕ U for the U of three blocks B_j (no kernel point: the search's case before) and the L
  // of two blocks A_i: the union of the blocks A_i ⊕ B_j, exact outside, the sign everywhere.
  // And C ⊖ U = ∩ C ⊖ B_j for a block C, exact inside.
  const double s = 0.1, h = 0.05;
  const Vec3 shift{-0.13, -0.04, -0.02};
  auto meshExpr = [](const Tool& m, const char* name) {
    std::vector<double> xyz;
    for (const Vec3& p : m.v) xyz.insert(xyz.end(), p.begin(), p.end());
    std::vector<uint32_t> tris;
    for (const auto& t : m.t) tris.insert(tris.end(), t.begin(), t.end());
    return fieldExpr(std::make_shared<MeshField>(xyz, tris, name), Expr::x(0), Expr::x(1), Expr::x(2));
  };
  Tool u = polyominoPrism(kU, h);
  for (Vec3& p : u.v) p = {s * p[0] + shift[0], s * p[1] + shift[1], p[2] + shift[2]};
  const Expr tool = meshExpr(u, "U tool");
  const std::array<std::array<Vec3, 2>, 3> B{{{Vec3{0, 0, 0}, Vec3{3 * s, s, h}},
                                              {Vec3{0, s, 0}, Vec3{s, 2 * s, h}},
                                              {Vec3{2 * s, s, 0}, Vec3{3 * s, 2 * s, h}}}};
  const double sa = 0.4, ha = 0.3;
  const Vec3 shiftA{-0.3, -0.2, -0.1};
  Tool l = polyominoPrism(kL, ha);
  for (Vec3& p : l.v) p = {sa * p[0] + shiftA[0], sa * p[1] + shiftA[1], p[2] + shiftA[2]};
  const std::array<std::array<Vec3, 2>, 2> A{
      {{Vec3{0, 0, 0}, Vec3{2 * sa, sa, ha}}, {Vec3{0, 0, 0}, Vec3{sa, 2 * sa, ha}}}};
  auto boxExpr = [](const Vec3& lo, const Vec3& hi) {
    Expr f = min(Expr::x(0) - lo[0], hi[0] - Expr::x(0));
    f = min(f, min(Expr::x(1) - lo[1], hi[1] - Expr::x(1)));
    return min(f, min(Expr::x(2) - lo[2], hi[2] - Expr::x(2)));
  };
  auto boxDistance = [](const Vec3& p, const Vec3& lo, const Vec3& hi) {
    double out = 0, in = INFINITY;
    for (size_t k = 0; k < 3; ++k) {
      const double d = std::max(lo[k] - p[k], p[k] - hi[k]);
      if (d > 0) out += d * d;
      in = std::min(in, -d);
    }
    return out > 0 ? -std::sqrt(out) : in;
  };
  auto eval = [](const Expr& e, const Vec3& p) {
    TapePtr t = Tape::compile(e, 3);
    PointEvaluator pe;
    return pe.eval(*t, p.data());
  };
  Expr sum;
  ASSERT_TRUE(minkowski::meshConvexSum(meshExpr(l, "L prism"), tool, 3, &sum));
  const auto term = minkowski::lookupExact(sum);
  ASSERT_TRUE(term);
  EXPECT_NE(term->operand.find("U tool (44 triangles) as 3 convex pieces"), std::string::npos) << term->operand;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> w(-0.6, 1.1), wh(-0.3, 0.4);
  int in = 0, out = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{w(rng), w(rng), wh(rng)};
    double e = -INFINITY;
    for (const auto& a : A)
      for (const auto& b : B) {
        const Vec3 lo = vec3::add(vec3::add(a[0], b[0]), vec3::add(shiftA, shift));
        const Vec3 hi = vec3::add(vec3::add(a[1], b[1]), vec3::add(shiftA, shift));
        e = std::max(e, boxDistance(p, lo, hi));
      }
    const double f = eval(sum, p);
    if (std::abs(e) < 1e-9) continue;
    ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
    if (e < 0) {
      EXPECT_NEAR(f, e, 1e-9) << p[0] << " " << p[1] << " " << p[2];
    }
    (e > 0 ? in : out) += 1;
  }
  EXPECT_GT(in, 300);
  EXPECT_GT(out, 300);

  const Vec3 clo{-0.3, -0.2, -0.1}, chi{0.4, 0.1, 0.2};
  Expr diff;
  ASSERT_TRUE(minkowski::meshConvexDifference(boxExpr(clo, chi), tool, 3, &diff));
  int inside = 0;
  std::uniform_real_distribution<double> wx(-0.3, 0.3), wy(-0.25, 0.05), wz(-0.15, 0.25);
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{wx(rng), wy(rng), wz(rng)};
    Vec3 lo{-INFINITY, -INFINITY, -INFINITY}, hi{INFINITY, INFINITY, INFINITY};
    for (const auto& b : B)
      for (size_t k = 0; k < 3; ++k)
        lo[k] = std::max(lo[k], clo[k] - b[0][k] - shift[k]), hi[k] = std::min(hi[k], chi[k] - b[1][k] - shift[k]);
    const double e = boxDistance(p, lo, hi), f = eval(diff, p);
    if (std::abs(e) < 1e-9) continue;
    ASSERT_EQ(f >= 0, e > 0) << p[0] << " " << p[1] << " " << p[2];
    if (e > 0) {
      ++inside;
      EXPECT_NEAR(f, e, 1e-9);
    }
  }
  EXPECT_GT(inside, 300);
}
