// The cancel-and-progress contract (frep/interrupt/interrupter.h): an interrupter that is never
// cancelled changes no result; a cancelled one makes sample, meshGrid, simplifyMesh, castRays
// and the extremum searches throw Interrupted before they finish (fewer searches than a whole
// run); measureMassProperties cancelled inside a round returns the last whole round's bounds.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "frep/extremum/extremum.h"
#include "frep/interrupt/interrupter.h"
#include "frep/measure/mass_properties.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/primitives/ops.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"

namespace frep {
namespace {

Expr x(uint32_t i) { return Expr::x(i); }
Expr len3(const Expr& a, const Expr& b, const Expr& c) { return sqrt(square(a) + square(b) + square(c)); }
Expr box3(const Expr& a, const Expr& b, const Expr& c, double h) {
  return min(min(h - abs(a), h - abs(b)), h - abs(c));
}

// A cube minus a ball, summed with a ball by branch-and-bound (a search at every point).
TapePtr minkowskiModel() {
  const Expr cubeMinusBall = min(box3(x(0), x(1), x(2), 1.0), len3(x(0), x(1), x(2)) - 1.2);
  const Expr ball = 0.3 - len3(x(0), x(1), x(2));
  MinkowskiOptions o;
  o.tolerance = 0.01;  // cheaper searches: the tests count them, not their digits
  return Tape::compile(minkowskiSum(cubeMinusBall, ball, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, o), 3);
}

GridSpec grid(int n) { return GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, n); }

uint64_t searches() { return extremumCounters().searches.load(); }

TEST(Interrupt, AnInterrupterNeverCancelledChangesNothingAndReportsEveryCube) {
  const TapePtr tape = minkowskiModel();
  SampleOptions plain;
  plain.threads = 2;
  const SampleResult a = sample(tape, grid(24), plain);
  std::vector<ProgressReport> seen;
  Interrupter run(nullptr, [&](const ProgressReport& p) {
    seen.push_back(p);
    return true;
  });
  SampleOptions watched = plain;
  watched.interrupt = &run;
  const SampleResult b = sample(tape, grid(24), watched);
  ASSERT_EQ(a.leaves.size(), b.leaves.size());
  for (size_t i = 0; i < a.leaves.size(); ++i) {
    EXPECT_EQ(a.leaves[i].origin, b.leaves[i].origin);
    EXPECT_EQ(a.leaves[i].values, b.leaves[i].values);
  }
  EXPECT_EQ(a.tiles.size(), b.tiles.size());
  ASSERT_FALSE(seen.empty());
  uint64_t most = 0;
  for (const ProgressReport& p : seen) {
    EXPECT_STREQ(p.stage, "sample");
    EXPECT_LE(p.done, p.total);
    most = std::max(most, p.done);
  }
  EXPECT_EQ(most, seen.front().total);  // the last cube reported is the total
}

TEST(Interrupt, ACancelledSampleThrowsBeforeItsSearchesAreDone) {
  const TapePtr tape = minkowskiModel();
  SampleOptions o;
  o.threads = 1;
  o.bandVoxels = 1;
  uint64_t before = searches();
  sample(tape, grid(48), o);  // work cubes of 32^3: 8
  const uint64_t whole = searches() - before;
  ASSERT_GT(whole, 100u);
  // Cancelled by its progress callback at the first cube done.
  Interrupter run(nullptr, [](const ProgressReport&) { return false; });
  o.interrupt = &run;
  before = searches();
  EXPECT_THROW(sample(tape, grid(48), o), Interrupted);
  EXPECT_LT(searches() - before, whole);
  EXPECT_TRUE(run.cancelled());
  // An outside flag (a signal handler's), set before the run: nothing is searched past the first check.
  std::atomic<bool> flag{true};
  Interrupter flagged(&flag);
  o.interrupt = &flagged;
  o.threads = 2;
  before = searches();
  EXPECT_THROW(sample(tape, grid(48), o), Interrupted);
  EXPECT_LT(searches() - before, whole / 4);
}

TEST(Interrupt, SearchesReachedThroughEvaluatorsSeeTheThreadsRun) {
  const TapePtr tape = minkowskiModel();
  ExtremumSolver solver(tape->extrema()[0].spec, tape->extrema()[0].body);
  const double X[3] = {1.1, 0.2, 0.0};
  const ExtremumResult r = solver.solve(X);
  EXPECT_TRUE(r.certified);
  Interrupter run;
  run.cancel();
  {
    InterruptScope scope(&run);
    EXPECT_THROW(solver.solve(X), Interrupted);
    EXPECT_THROW(solver.solveSign(X), Interrupted);
    PointEvaluator pe;
    EXPECT_THROW(pe.eval(*tape, X), Interrupted);
    {
      InterruptScope none(nullptr);  // a nested run without an interrupter
      EXPECT_EQ(solver.solve(X).value, r.value);
    }
    EXPECT_THROW(solver.solve(X), Interrupted);  // the outer scope is back
  }
  EXPECT_EQ(solver.solve(X).value, r.value);
}

TEST(Interrupt, MeshSimplifyAndRenderThrowWhenCancelled) {
  const TapePtr tape = minkowskiModel();
  std::atomic<bool> flag{false};
  Interrupter run(&flag);
  MeshOptions mo;
  mo.interrupt = &run;
  Mesh mesh = meshGrid(tape, grid(16), mo);  // not cancelled: the whole mesh
  ASSERT_FALSE(mesh.triangles.empty());
  flag = true;
  EXPECT_THROW(meshGrid(tape, grid(16), mo), Interrupted);

  // The simplifier on a sphere's mesh (no searches: its own checks stop it).
  const Expr sphere = 1.0 - square(x(0)) - square(x(1)) - square(x(2));
  const TapePtr sphereTape = Tape::compile(sphere, 3);
  Mesh round = meshGrid(sphereTape, grid(24));
  SimplifyOptions so;
  so.tolerance = 0.2;
  so.interrupt = &run;
  const size_t triangles = round.triangles.size();
  EXPECT_THROW(simplifyMesh(round, sphereTape, grid(24), so), Interrupted);
  flag = false;
  Mesh again = meshGrid(sphereTape, grid(24));
  simplifyMesh(again, sphereTape, grid(24), so);
  EXPECT_LT(again.triangles.size(), triangles);

  RenderOptions ro;
  ro.width = ro.height = 64;
  ro.nearDepth = 1, ro.farDepth = 8;
  ro.interrupt = &run;
  const Camera cam = orbitCamera({0, 0, 0}, 30, 20, 4, false, 1.5);
  std::vector<ProgressReport> seen;
  Interrupter counted(nullptr, [&](const ProgressReport& p) {
    seen.push_back(p);
    return true;
  });
  ro.interrupt = &counted;
  ro.threads = 1;
  castRays(sphere, cam, ro);
  ASSERT_EQ(seen.size(), 4u);  // 2 x 2 tiles of 32 pixels
  EXPECT_STREQ(seen.back().stage, "render");
  EXPECT_EQ(seen.back().done, 4u);
  EXPECT_EQ(seen.back().total, 4u);
  ro.interrupt = &run;
  flag = true;
  EXPECT_THROW(castRays(sphere, cam, ro), Interrupted);
}

TEST(Interrupt, MeasureCancelledInsideARoundKeepsTheLastWholeRound) {
  const Expr ball = 1.0 - square(x(0)) - square(x(1)) - square(x(2));
  const Interval box[3] = {{-1.25, 1.25}, {-1.25, 1.25}, {-1.25, 1.25}};
  const double exact = 4.0 / 3.0 * M_PI;
  // Stopped between rounds by the progress callback after round 2.
  MeasureOptions between;
  between.threads = 1;
  between.progress = [](const MeasureProgress& p) { return p.round < 2; };
  const MassProperties a = measureMassProperties(ball, box, between);
  ASSERT_TRUE(a.stopped);
  ASSERT_EQ(a.rounds, 2);
  // Cancelled at the same point, but seen only by the next round's first check (inside it):
  // that round's children are dropped and its parents measured again.
  Interrupter run;
  MeasureOptions inside;
  inside.threads = 1;
  inside.interrupt = &run;
  inside.progress = [&](const MeasureProgress& p) {
    if (p.round == 2) run.cancel();
    return true;
  };
  const MassProperties b = measureMassProperties(ball, box, inside);
  EXPECT_TRUE(b.stopped);
  EXPECT_EQ(b.stopReason, "cancelled");
  EXPECT_EQ(b.rounds, 2);
  EXPECT_EQ(b.boundaryCells, a.boundaryCells);
  EXPECT_LE(b.volume.lower, exact);
  EXPECT_GE(b.volume.upper, exact);
  EXPECT_NEAR(b.volume.lower, a.volume.lower, 1e-12 * exact);  // the same leaves, summed in another order
  EXPECT_NEAR(b.volume.upper, a.volume.upper, 1e-12 * exact);
  // Cancelled before the first round ends: no bounds at all.
  Interrupter early;
  early.cancel();
  inside.interrupt = &early;
  EXPECT_THROW(measureMassProperties(ball, box, inside), Interrupted);
}

TEST(Interrupt, ACancelFromAnotherThreadEndsALongSample) {
  // A grid whose sample takes seconds; cancelled once the first cube is done. Checks only that
  // it ends with Interrupted and fewer searches than the whole grid has points near the surface.
  const TapePtr tape = minkowskiModel();
  std::atomic<bool> flag{false}, started{false};
  Interrupter run(&flag, [&](const ProgressReport&) {
    started = true;
    return true;
  });
  SampleOptions o;
  o.threads = 2;
  o.interrupt = &run;
  std::thread canceller([&] {
    while (!started) std::this_thread::yield();
    flag = true;
  });
  const uint64_t before = searches();
  EXPECT_THROW(sample(tape, grid(160), o), Interrupted);
  canceller.join();
  const uint64_t done = searches() - before;
  const GridSpec g = grid(160);
  EXPECT_LT(done, uint64_t(g.dims[0]) * uint64_t(g.dims[1]) * 12u);  // the surface's band alone has more
}

}  // namespace
}  // namespace frep
