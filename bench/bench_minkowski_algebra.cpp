// Roerdink's exact Minkowski algebra against the certified extremum search (issue 12): a 4-term
// sum in a rotated frame, sampled with frep::sample on one thread at 256³ over [-1.5, 1.5]³.
//   default:   xline(1.6) ⊕ yline(1.0) ⊕ zdisc(0.4) ⊕ sphere(0.25) (one disc axis: one closed form,
//              the discus distance at the excess over the block);
//   --bidisc:  xline ⊕ yline ⊕ zdisc(0.4) ⊕ xdisc(0.25) (two disc axes: the bidisc gauge);
//   --discs:   xline(1.6) ⊕ zdisc(0.4) ⊕ xdisc(0.25) ⊕ sphere(0.15) (two disc axes and a sphere, the
//              bicircle-sphere R12: the convex-projection field of disc_sum_distance.h).
//   exact:  unionExpr of the reduction (no search, error bound 0);
//   search: the cheapest search form of the same solid, ONE 3D branch-and-bound per voxel: (exact
//           field of the first three terms) ⊕ (the fourth by its own formula), gap 1e-3 (the fold
//           that frMinkowskiSum would run without the algebra nests three searches: one point of it
//           took 233 CPU s in a trial run, so it is not measured). In the default mode the first
//           three terms are given two ways: as the union of their ray-tracer pieces (max of 6
//           SDFs, the head of earlier runs) and as the one closed form. The search is run on the
//           pencil y, z ∈ [res/2, res/2 + 8) (all x), where its interval bounds cannot prune and
//           it samples every voxel; the whole grid is extrapolated as its CPU time per sampled
//           voxel × the voxels the EXACT run samples (the narrow band): a lower bound for the
//           search, which prunes no better than the exact field. --full-search runs it all.
// CPU seconds of this process (bench_timing.h), medians of 3 interleaved runs; the ratios use
// the same run's figures.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "bench_timing.h"
#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/minkowski_algebra/reduction.h"
#include "frep/sampling/sample.h"

using namespace frep;
using namespace frep::minkowski;
using frep::bench::cpuSeconds;

namespace {

Shape member(ShapeKind k, int axis, double size, const Mat3& rot) {
  Shape s;
  s.kind = k;
  s.axis = axis;
  s.size[0] = size;
  s.rot = rot;
  return s;
}

struct Run {
  double seconds = 0;
  uint64_t voxels = 0;
};

Run runSample(const Expr& f, const GridSpec& g, int zlo, int zhi) {
  TapePtr t = Tape::compile(f, 3);
  SampleOptions o;
  o.threads = 1;
  if (zlo >= 0) {
    o.regionLo = {0, zlo, zlo};
    o.regionHi = {-1, zhi, zhi};
  }
  const double c0 = cpuSeconds();
  SampleResult r = sample(t, g, o);
  return {cpuSeconds() - c0, r.stats.pointEvals};
}

}  // namespace

int main(int argc, char** argv) {
  bool fullSearch = false, bidisc = false, discs = false;
  int res = 256;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--full-search")) fullSearch = true;
    if (!std::strcmp(argv[i], "--bidisc")) bidisc = true;
    if (!std::strcmp(argv[i], "--discs")) discs = true;
    if (!std::strcmp(argv[i], "--res") && i + 1 < argc) res = std::atoi(argv[++i]);
  }
  const Mat3 rot = rotationXYZ(0.3, -0.2, 0.5);
  Sum head, all;
  std::vector<Shape> first = {member(ShapeKind::Segment, 0, 1.6, rot), member(ShapeKind::Segment, 1, 1.0, rot),
                              member(ShapeKind::Disc, 2, 0.4, rot)};
  if (discs) first[1] = member(ShapeKind::Disc, 0, 0.25, rot);
  for (const Shape& s : first) head.add(s);
  all = head;
  const double ballRadius = discs ? 0.15 : 0.25;
  all.add(bidisc ? member(ShapeKind::Disc, 0, 0.25, rot) : member(ShapeKind::Sphere, 0, ballRadius, rot));
  // Centre the solid: move the local origin to -R·(L/2).
  Vec3 half{-0.8, discs ? 0.0 : -0.5, 0};
  for (int i = 0; i < 3; ++i) {
    double w = rot[i * 3] * half[0] + rot[i * 3 + 1] * half[1] + rot[i * 3 + 2] * half[2];
    head.offset[i] = all.offset[i] = w;
  }
  Reduction rAll = reduce(all), rHead = reduce(head);
  Expr exact = unionExpr(rAll);
  Expr ball = ballRadius - sqrt(square(Expr::x(0)) + square(Expr::x(1)) + square(Expr::x(2)));
  if (bidisc) {  // minus the distance to xdisc(0.25) in the rotated frame
    const Expr h = Expr::x(0) * rot[0] + Expr::x(1) * rot[3] + Expr::x(2) * rot[6];
    const Expr rho = sqrt(square(Expr::x(0) - h * rot[0]) + square(Expr::x(1) - h * rot[3]) +
                          square(Expr::x(2) - h * rot[6]));
    ball = -sqrt(square(h) + square(max(rho - 0.25, Expr(0.0))));
  }
  MinkowskiOptions mo;
  mo.tolerance = 1e-3;
  const Bounds box{{-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}};
  const std::vector<Expr> xyz{Expr::x(0), Expr::x(1), Expr::x(2)};
  struct Baseline {
    const char* name;
    Expr field;
  };
  std::vector<Baseline> searches = {{"search (head: one closed form / gauge)", minkowskiSum(unionExpr(rHead), ball, 3, box, mo)}};
  if (!bidisc && !discs)
    searches.insert(searches.begin(), {"search (head: union of its 6 pieces)",
                                       minkowskiSum(piecesUnionExpr(rHead, xyz), ball, 3, box, mo)});
  std::printf("sum: %s, %zu primitives\n", all.describe().c_str(), primitives(rAll).size());

  GridSpec g = GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, res);
  const int zlo = (res / 2) / 8 * 8, zhi = zlo + 8;
  // Each figure is the median of 3 runs, the exact and the search runs interleaved (the machine
  // is shared: CPU time per run moves with the load).
  const int reps = fullSearch ? 1 : 3;
  std::vector<std::vector<double>> times(1 + searches.size());
  Run ex, exSlab;
  std::vector<Run> se(searches.size());
  for (int rep = 0; rep < reps; ++rep) {
    ex = runSample(exact, g, -1, -1);
    times[0].push_back(ex.seconds);
    for (size_t b = 0; b < searches.size(); ++b) {
      se[b] = fullSearch ? runSample(searches[b].field, g, -1, -1) : runSample(searches[b].field, g, zlo, zhi);
      times[1 + b].push_back(se[b].seconds);
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  ex.seconds = median(times[0]);
  exSlab = runSample(exact, g, zlo, zhi);
  std::printf("exact  %d^3: %.3f CPU s (median of %d), %llu sampled voxels (%.1f ns each)\n", res, ex.seconds, reps,
              (unsigned long long)ex.voxels, 1e9 * ex.seconds / double(ex.voxels));
  std::printf("exact  pencil: %.4f CPU s on %llu voxels\n", exSlab.seconds, (unsigned long long)exSlab.voxels);
  for (size_t b = 0; b < searches.size(); ++b) {
    se[b].seconds = median(times[1 + b]);
    const double searchFull = fullSearch ? se[b].seconds : se[b].seconds / double(se[b].voxels) * double(ex.voxels);
    std::printf("%s %d^3%s: %.3f CPU s on %llu voxels", searches[b].name, res,
                fullSearch ? "" : (" pencil y, z in [" + std::to_string(zlo) + ", " + std::to_string(zhi) + ")").c_str(),
                se[b].seconds, (unsigned long long)se[b].voxels);
    if (!fullSearch)
      std::printf(" (%.2f us each); x the exact run's %llu band voxels: %.3f CPU s",
                  1e6 * se[b].seconds / double(se[b].voxels), (unsigned long long)ex.voxels, searchFull);
    std::printf("\n  ratio search / exact: %.0fx (error bound: exact 0, search %.0e)\n", searchFull / ex.seconds,
                mo.tolerance);
  }

  // Sign agreement at random points away from the search's gap.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  TapePtr te = Tape::compile(exact, 3), ts = Tape::compile(searches.back().field, 3);
  PointEvaluator pe;
  int compared = 0, disagree = 0;
  for (int i = 0; i < 4000; ++i) {
    double p[3] = {u(rng), u(rng), u(rng)};
    double e = pe.eval(*te, p);
    if (std::fabs(e) < 0.01) continue;
    double s = pe.eval(*ts, p);
    ++compared;
    disagree += (e > 0) != (s >= -2e-3);
  }
  std::printf("sign check: %d random points, %d disagreements\n", compared, disagree);
  return 0;
}
