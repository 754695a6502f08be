// Extremum node benchmarks (figures and ratios measured in the same run; never fail on time):
//  1. fast (interval branch-and-bound, warm-started from the previous voxel in the batch) vs the
//     paper's eps-grid with quadratic refinement, at the same error bound, on the non-convex pair
//     (cube 10 - sphere r 6) + sphere r 1, both sampled with frep::sample (same narrow band, same
//     interval classification) at 64^3; at 128^3 the grid is measured on a random subset of the
//     band voxels and extrapolated (it would take half an hour);
//  2. the same pair with the paper's a = 0 R-intersection (Pasko-Minkowski eq. 3.3) in the body:
//     whether B&B certifies, and its cost (grid extrapolated from a subset at the same eps);
//  3. box + ball volume (inside voxels x voxel volume) against Steiner's formula;
//  4. (--signs) the mesher's sample of issue 17's non-convex slab + ball (band 0, a cold search
//     per point): full searches vs sign-only searches (ExtremumSolver::solveSign), same signs.
// Times are CPU seconds of this process (single thread; the machine may be shared), wall
// seconds in brackets; ratios use CPU seconds.
// Usage: bench_extremum [--quick | --128 | --a0 | --steiner | --signs]   (--quick: 64^3 only)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

#include "bench_timing.h"

using namespace frep;
using frep::bench::cpuSeconds;

namespace {

constexpr double kPi = 3.141592653589793;

Expr X() { return Expr::x(0); }
Expr Y() { return Expr::x(1); }
Expr Z() { return Expr::x(2); }
Expr len() { return sqrt(square(X()) + square(Y()) + square(Z())); }
Expr boxSdf(double a, double b, double c) { return min(min(a - abs(X()), b - abs(Y())), c - abs(Z())); }

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Run {
  double seconds = 0, wall = 0;
  uint64_t bodyEvals = 0, searchEvals = 0, boundEvals = 0, voxels = 0, uncertified = 0;
  SampleResult res;
};

Run runSample(const Expr& model, const GridSpec& g) {
  TapePtr t = Tape::compile(model);
  resetExtremumCounters();
  SampleOptions o;
  o.threads = 1;  // one core on both sides of every ratio
  auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpuSeconds();
  Run r;
  r.res = sample(t, g, o);
  r.seconds = cpuSeconds() - c0;
  r.wall = seconds(t0);
  auto& c = extremumCounters();
  r.searchEvals = c.pointEvals + c.intervalEvals;
  r.boundEvals = c.boundIntervalEvals;
  r.bodyEvals = r.searchEvals + r.boundEvals;
  r.voxels = r.res.stats.pointEvals;
  r.uncertified = c.uncertified;
  return r;
}

// a: the R-intersection in the Minkowski body (1: min, the default; 0: Pasko-Minkowski eq. 3.3).
void fastVsGrid(int res, bool fullGrid, double a = 1.0) {
  // (cube 10 - sphere r 6) + sphere r 1: the sphere cuts the cube's faces, leaving a non-convex
  // shell of eight corner pieces.
  Expr A = min(boxSdf(5, 5, 5), len() - 6.0);
  Expr B = 1.0 - len();
  GridSpec g = GridSpec::fromBounds({-6.5, -6.5, -6.5}, {6.5, 6.5, 6.5}, res);
  // Equal error bound E = half a voxel on the value (the a = 1 body is 1-Lipschitz in u): the
  // grid's covering radius sqrt(3)/2 eps = E, the B&B certified gap = E. (With a = 0 the body's
  // Lipschitz constant is up to 2 + sqrt(2), so the same eps only bounds the grid's error by
  // 3.4 E: the comparison then favours the grid.)
  const double E = 0.5 * g.voxel;
  MinkowskiOptions fast;
  fast.method = ExtremumMethod::BranchAndBound;
  fast.tolerance = E;
  fast.a = a;
  MinkowskiOptions grid;
  grid.method = ExtremumMethod::Grid;
  grid.eps = 2.0 * E / std::sqrt(3.0);
  grid.tolerance = E;
  grid.a = a;
  Bounds bb{{-1, -1, -1}, {1, 1, 1}};
  Expr mFast = minkowskiSum(A, B, 3, bb, fast);
  Expr mGrid = minkowskiSum(A, B, 3, bb, grid);
  const int nodes = int(std::ceil(2.0 / grid.eps - 1e-9)) + 1;

  std::printf("\n(cube 10 - sphere r6) + sphere r1%s at %d^3 (voxel %.4f), error bound E = %.4f\n",
              a == 1.0 ? "" : ", body with the a = 0 R-intersection (eq. 3.3)", res, g.voxel, E);
  std::printf("  grid eps %.4f (%d^3 = %d nodes per voxel + refinement), B&B tolerance %.4f\n", grid.eps, nodes,
              nodes * nodes * nodes, E);
  Run f = runSample(mFast, g);
  std::printf("  %-28s %9s %9s %14s %14s %12s %10s\n", "method", "cpu s", "(wall s)", "body evals", "per voxel",
              "band voxels", "uncert.");
  std::printf("  %-28s %9.3f %9.3f %14llu %14.1f %12llu %10llu\n", "B&B + warm start", f.seconds, f.wall,
              (unsigned long long)f.bodyEvals, double(f.searchEvals) / double(f.voxels),
              (unsigned long long)f.voxels, (unsigned long long)f.uncertified);
  std::printf("    (of which interval classification of boxes: %llu body interval evals)\n",
              (unsigned long long)f.boundEvals);
  double gridSeconds = 0, gridEvals = 0;
  if (fullGrid) {
    Run gr = runSample(mGrid, g);
    gridSeconds = gr.seconds;
    gridEvals = double(gr.bodyEvals);
    std::printf("  %-28s %9.3f %9.3f %14llu %14.1f %12llu\n", "grid + quadratic (paper)", gr.seconds, gr.wall,
                (unsigned long long)gr.bodyEvals, double(gr.searchEvals) / double(gr.voxels),
                (unsigned long long)gr.voxels);
    // accuracy: both within E of each other at every band voxel
    double maxDiff = 0;
    for (size_t i = 0; i < f.res.leaves.size() && i < gr.res.leaves.size(); ++i)
      for (int o = 0; o < kLeafVoxels; ++o)
        if (f.res.leaves[i].isActive(o) && gr.res.leaves[i].isActive(o))
          maxDiff = std::max(maxDiff, double(std::fabs(f.res.leaves[i].values[o] - gr.res.leaves[i].values[o])));
    std::printf("    max |B&B - grid| over band voxels: %.4f (both within E = %.4f of the true value)\n", maxDiff, E);
  } else {
    // The grid costs the same per voxel everywhere: time it on a random subset of band voxels.
    TapePtr t = Tape::compile(mGrid);
    ExtremumSolver solver(t->extrema()[0].spec, t->extrema()[0].body);
    std::vector<std::array<double, 3>> pts;
    for (const LeafBlock& l : f.res.leaves)
      for (int o = 0; o < kLeafVoxels; ++o)
        if (l.isActive(o)) pts.push_back(g.world(l.origin[0] + (o >> 6), l.origin[1] + ((o >> 3) & 7), l.origin[2] + (o & 7)));
    std::mt19937_64 rng(1);
    std::shuffle(pts.begin(), pts.end(), rng);
    const size_t k = std::min<size_t>(pts.size(), 600);
    resetExtremumCounters();
    auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpuSeconds();
    for (size_t i = 0; i < k; ++i) solver.solveGrid(pts[i].data());
    const double s = cpuSeconds() - c0, w = seconds(t0);
    const double perVoxel = double(extremumCounters().pointEvals) / double(k);
    gridSeconds = s / double(k) * double(f.voxels);
    gridEvals = perVoxel * double(f.voxels) + double(f.boundEvals);
    std::printf("  %-28s %9.1f %9.1f %14.3g %14.1f %12llu   (extrapolated from %zu voxels)\n",
                "grid + quadratic (paper)", gridSeconds, w / double(k) * double(f.voxels), gridEvals, perVoxel,
                (unsigned long long)f.voxels, k);
  }
  std::printf("  ratios grid / B&B: time %.1fx, body evaluations %.1fx (targets >= 50x, >= 100x)\n",
              gridSeconds / f.seconds, gridEvals / double(f.bodyEvals));
}

void steiner(int res) {
  const double a = 2.0, b = 1.5, c = 1.0, r = 0.25;
  Expr box = boxSdf(a / 2, b / 2, c / 2);
  Expr ball = r - len();
  MinkowskiOptions o;
  // Bounds chosen so that no lattice plane coincides with a face of the shape (points exactly
  // on the surface have value 0 +- tolerance, and a whole aligned layer would flip together).
  GridSpec g = GridSpec::fromBounds({-1.4137, -1.4071, -1.4029}, {1.4137, 1.4071, 1.4029}, res);
  o.tolerance = 0.05 * g.voxel;  // the value grows at 1/2 per unit of X: the surface within 0.1 voxel
  Expr m = minkowskiSum(box, ball, 3, {{-r, -r, -r}, {r, r, r}}, o);
  Run run = runSample(m, g);
  const double exact = a * b * c + 2 * (a * b + b * c + c * a) * r + kPi * (a + b + c) * r * r + 4 * kPi * r * r * r / 3;
  const double v = insideVolume(run.res);
  // The same voxel count for the exact rounded box (distance to the box <= r) on the same
  // lattice: separates the lattice's own counting error from the search's.
  const double vExact = latticeVolume(g, [&](const std::array<double, 3>& p) {
    const double dx = std::max(0.0, std::fabs(p[0]) - a / 2), dy = std::max(0.0, std::fabs(p[1]) - b / 2),
                 dz = std::max(0.0, std::fabs(p[2]) - c / 2);
    return dx * dx + dy * dy + dz * dz <= r * r;
  });
  std::printf("  %4d^3: volume %.5f vs Steiner %.5f: rel. error %+.3f%%; exact shape on the same lattice %.5f "
              "(%+.3f%%), sampled vs exact-lattice %+.3f%%  (%.2f cpu s, %llu band voxels, voxel %.4f)\n",
              res, v, exact, 100 * (v - exact) / exact, vExact, 100 * (vExact - exact) / exact,
              100 * (v - vExact) / vExact, run.seconds, (unsigned long long)run.voxels, g.voxel);
}

// The mesher's sample of an extremum model (docs/mesh.md): band 0, cold searches; full values vs
// sign-only searches, on the L-shaped plate (+) ball r 0.3 of bench_minkowski_peers.py (min/max
// form, B&B gap 1e-3, searched box = the ball's), over [-1.5, 1.5]^3.
void signOnlySampling(int res) {
  const Expr slab = min(min(min(min(X() + 1, 1 - X()), min(Y() + 1, 1 - Y())), min(Z() + 0.25, 0.25 - Z())),
                        -min(min(min(X() + 0.2, 1.3 - X()), min(Y() + 0.2, 1.3 - Y())), min(Z() + 1, 1 - Z())));
  const Expr ball = 0.09 - square(X()) - square(Y()) - square(Z());
  TapePtr t = Tape::compile(minkowskiSum(slab, ball, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, MinkowskiOptions{}));
  GridSpec g = GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, res);
  std::printf("\nnon-convex slab + ball r 0.3 at %d^3: the mesher's sample (band 0, a cold search per point)\n", res);
  std::printf("  %-28s %9s %14s %10s\n", "searches", "cpu s", "search evals", "points");
  SampleResult r[2];
  double cpu[2];
  uint64_t evals[2];
  for (int signs = 0; signs < 2; ++signs) {
    SampleOptions o;
    o.threads = 1;
    o.bandVoxels = 0;
    o.pointwiseSearches = true;
    o.extremumSignsOnly = signs == 1;
    resetExtremumCounters();
    const double c0 = cpuSeconds();
    r[signs] = sample(t, g, o);
    cpu[signs] = cpuSeconds() - c0;
    evals[signs] = extremumCounters().pointEvals + extremumCounters().intervalEvals;
    std::printf("  %-28s %9.3f %14llu %10llu\n", signs ? "sign only (solveSign)" : "full (cold solve)", cpu[signs],
                (unsigned long long)evals[signs], (unsigned long long)r[signs].stats.pointEvals);
  }
  uint64_t differ = 0, points = 0;
  for (size_t i = 0; i < r[0].leaves.size() && i < r[1].leaves.size(); ++i)
    for (int off = 0; off < kLeafVoxels; ++off) {
      if (!r[0].leaves[i].isActive(off)) continue;
      ++points;
      differ += std::signbit(r[0].leaves[i].values[off]) != std::signbit(r[1].leaves[i].values[off]);
    }
  std::printf("  sign only / full: cpu %.2fx less, search evaluations %.2fx fewer; signs differing: %llu of %llu\n",
              cpu[0] / cpu[1], double(evals[0]) / double(evals[1]), (unsigned long long)differ,
              (unsigned long long)points);
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const bool only128 = argc > 1 && std::strcmp(argv[1], "--128") == 0;
  const bool onlyA0 = argc > 1 && std::strcmp(argv[1], "--a0") == 0;
  const bool onlySteiner = argc > 1 && std::strcmp(argv[1], "--steiner") == 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc > 1 && std::strcmp(argv[1], "--signs") == 0) {
    signOnlySampling(48);
    signOnlySampling(96);
    return 0;
  }
  std::printf("Extremum node: fast (B&B) vs the paper's grid search at equal error bound, single thread\n");
  if (!only128 && !onlySteiner && !onlyA0) fastVsGrid(64, true);
  if (!quick && !onlySteiner && !onlyA0) fastVsGrid(128, false);
  if (only128) return 0;
  if (!onlySteiner) fastVsGrid(64, false, 0.0);
  if (!quick && !onlySteiner) fastVsGrid(128, false, 0.0);
  if (onlyA0) return 0;
  std::printf("\nbox 2 x 1.5 x 1 + ball r 0.25: voxel-count volume vs Steiner abc + 2(ab+bc+ca)r + pi(a+b+c)r^2 + 4/3 pi r^3\n");
  steiner(64);
  if (!quick) steiner(128);
  return 0;
}
