// A closed mesh's distance offset as one field (geometry/mesh_offset_field.h): its values are
// the mesh field's plus the level, bit for bit, and its signs() — "is some triangle within r",
// the cell's centre class, the fallback to the value — give the class of those values at the
// points the simplifier asks about (pairs a hair either side of the offset surface) and
// everywhere else; the cell lists behind them are built on a cell's second query.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "core/mesh_models.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/expressions/tape.h"
#include "frep/geometry/cell_lists.h"
#include "frep/geometry/mesh_offset_field.h"

namespace frep {
namespace {

constexpr double kR = 0.8, kTube = 0.3;

// The torus of radii kR, kTube as a closed mesh field of nu x nv quads.
std::shared_ptr<const MeshField> torusMesh(int nu, int nv) {
  const mesh_models::TorusSoup s = mesh_models::torusSoup(kR, kTube, nu, nv);
  return std::make_shared<MeshField>(s.xyz, s.tris, "torus");
}

// Pairs a hair, a few hairs or up to 0.06 either side of the offset surface at `level` (from
// the mesh's nearest point q of a point x near it, along x - q: |p - q| is the distance while
// q stays nearest), and points of the whole box.
std::vector<std::array<double, 3>> pointsAround(const MeshField& mesh, double level, std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), wide(-0.06, 0.06), box(-1.3, 1.3);
  std::vector<std::array<double, 3>> pts;
  const double hairs[] = {1e-9, 1e-6, 1e-4, 1e-3, 0.01};
  for (int i = 0; i < 3000; ++i) {
    const double u = angle(rng), w = angle(rng), t = kTube + level;
    const double x[3] = {(kR + t * std::cos(w)) * std::cos(u), (kR + t * std::cos(w)) * std::sin(u), t * std::sin(w)};
    double q[3];
    const double d = mesh.distance(x, q);
    if (!(d > 0)) continue;
    const double base = std::fabs(level) + (i % 6 == 5 ? wide(rng) : 0.0);
    for (double e : {-hairs[i % 5], hairs[i % 5]})
      pts.push_back({q[0] + (base + e) * (x[0] - q[0]) / d, q[1] + (base + e) * (x[1] - q[1]) / d,
                     q[2] + (base + e) * (x[2] - q[2]) / d});
  }
  for (int i = 0; i < 3000; ++i) pts.push_back({box(rng), box(rng), 0.4 * box(rng)});
  return pts;
}

TEST(MeshOffsetField, SignsAreTheClassesOfItsValues) {
  const auto mesh = torusMesh(64, 32);
  ASSERT_TRUE(mesh->check().closed());
  std::mt19937 rng(17);
  // Levels above and below the lattice's cell (2.2 / 64: the centre's class decides only
  // beyond it), sums and erosions.
  for (double level : {0.05, 0.2, 0.01, -0.05, -0.12}) {
    const MeshOffsetField f(mesh, level);
    const auto pts = pointsAround(*mesh, level, rng);
    std::vector<double> values(pts.size());
    int near = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      values[i] = f.value(pts[i].data());
      const double sum = mesh->value(pts[i].data()) + level;
      ASSERT_EQ(std::memcmp(&values[i], &sum, sizeof sum), 0) << "level " << level << " point " << i;
      near += std::fabs(values[i]) <= 1e-3;
    }
    EXPECT_GT(near, 3000) << "level " << level;  // 4 pairs in 6 within 1e-3
    // In a shuffled order, twice (the first pass leaves most cells seen once: no lists yet),
    // in batches as the simplifier asks.
    std::vector<size_t> order(pts.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    for (int pass = 0; pass < 2; ++pass) {
      std::shuffle(order.begin(), order.end(), rng);
      constexpr size_t kBatch = 64;
      for (size_t b = 0; b < order.size(); b += kBatch) {
        const size_t n = std::min(kBatch, order.size() - b);
        double u[kBatch], v[kBatch], w[kBatch], out[kBatch];
        for (size_t j = 0; j < n; ++j) {
          const auto& p = pts[order[b + j]];
          u[j] = p[0], v[j] = p[1], w[j] = p[2];
        }
        f.signs(u, v, w, out, n);
        for (size_t j = 0; j < n; ++j) {
          const double value = values[order[b + j]];
          if (value == 0) continue;  // on the surface either class is right
          ASSERT_EQ(out[j] >= 0, value >= 0)
              << "level " << level << " point " << order[b + j] << " pass " << pass << " value " << value;
        }
      }
    }
  }
}

// As the simplifier evaluates it: the field call last in a tape, in sign-only mode, gives the
// classes of the values the same tape gives in full (a translated ball sum).
TEST(MeshOffsetField, SignOnlyTapesGiveTheClassesOfTheFullTapes) {
  const auto mesh = torusMesh(48, 24);
  const Expr f =
      fieldCall(std::make_shared<MeshOffsetField>(mesh, 0.07), Expr::x(0) - 0.1, Expr::x(1) + 0.05, Expr::x(2));
  const TapePtr tape = Tape::compile(f, 3);
  ASSERT_EQ(tape->code().back().op, Op::Field);
  std::mt19937 rng(3);
  auto pts = pointsAround(*mesh, 0.07, rng);
  for (auto& p : pts) p[0] += 0.1, p[1] -= 0.05;
  BatchEvaluator<double> full, signs;
  signs.setFieldSignsOnly(true);
  full.reserve(*tape), signs.reserve(*tape);
  size_t compared = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (size_t b = 0; b < pts.size(); b += BatchEvaluator<double>::kBatch) {
      const size_t n = std::min(BatchEvaluator<double>::kBatch, pts.size() - b);
      for (BatchEvaluator<double>* e : {&full, &signs})
        for (uint32_t k = 0; k < 3; ++k)
          for (size_t j = 0; j < n; ++j) e->in(k)[j] = pts[b + j][k];
      const double* v = full.eval(*tape, n);
      const std::vector<double> values(v, v + n);
      const double* classes = signs.eval(*tape, n);
      for (size_t j = 0; j < n; ++j) {
        if (values[j] == 0) continue;  // on the surface either class is right
        ASSERT_EQ(classes[j] >= 0, values[j] >= 0) << "point " << b + j;
        ++compared;
      }
    }
  EXPECT_GT(compared, 15000u);  // two passes over 9,000 points
}

TEST(MeshOffsetField, BoundsGradientsAndIdentity) {
  const auto mesh = torusMesh(32, 16);
  const MeshOffsetField sum(mesh, 0.1), same(mesh, 0.1), other(mesh, -0.1);
  EXPECT_TRUE(sum.sameContent(same));
  EXPECT_EQ(sum.contentHash(), same.contentHash());
  EXPECT_FALSE(sum.sameContent(other));
  EXPECT_NE(sum.describe().find("torus + 0.1"), std::string::npos) << sum.describe();
  const double p[3] = {1.25, 0.1, 0.05};
  double g[3], gm[3];
  EXPECT_EQ(sum.gradient(p, g), mesh->gradient(p, gm) + 0.1);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(g[k], gm[k]);
  const Interval box[3] = {{1.0, 1.2}, {-0.1, 0.1}, {-0.1, 0.1}};
  const Interval b = sum.bound(box), bm = mesh->bound(box);
  EXPECT_LE(b.lo, bm.lo + 0.1);
  EXPECT_GE(b.hi, bm.hi + 0.1);
  EXPECT_THROW(MeshOffsetField(mesh, 0.0), std::invalid_argument);
  EXPECT_THROW(MeshOffsetField(mesh, NAN), std::invalid_argument);
}

TEST(CellLists, BuildsACellsListOnItsSecondQuery) {
  const uint64_t owner = CellLists::newOwner();
  int builds = 0;
  auto build = [&](std::vector<uint32_t>& out) {
    ++builds;
    out.push_back(7);
    return true;
  };
  uint32_t count = 0;
  EXPECT_EQ(CellLists::get(owner, 1, count, build), nullptr);  // seen once: no list
  EXPECT_EQ(builds, 0);
  const uint32_t* list = CellLists::get(owner, 1, count, build);  // twice: built
  ASSERT_NE(list, nullptr);
  EXPECT_EQ(builds, 1);
  EXPECT_EQ(count, 1u);
  EXPECT_EQ(list[0], 7u);
  EXPECT_EQ(CellLists::get(owner, 2, count, build), nullptr);
  ASSERT_NE(CellLists::get(owner, 1, count, build), nullptr);  // kept
  EXPECT_EQ(builds, 1);
  // A cell given no list stays without one, built once.
  auto none = [&](std::vector<uint32_t>&) {
    ++builds;
    return false;
  };
  EXPECT_EQ(CellLists::get(owner, 3, count, none), nullptr);
  EXPECT_EQ(CellLists::get(owner, 3, count, none), nullptr);
  EXPECT_EQ(CellLists::get(owner, 3, count, none), nullptr);
  EXPECT_EQ(builds, 2);
}

}  // namespace
}  // namespace frep
