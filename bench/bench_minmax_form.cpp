// Minkowski sums of operands written with HyperFun's sqrt R-functions (hfBlock's
// (sx &0 sy) &0 sz and '\'), searched in their min/max form (frep/expressions/min_max_form.h)
// or as written, against the same solid written with min/max of half-spaces, in one run:
// sampling a non-convex slab (+) ball at N^3 (default 48), CPU seconds on one thread, and the
// ratios. Usage: bench_minmax_form [N]
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>

#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec);
}

// hfBlock: (sx &0 sy) &0 sz with sx = (x - vx)(vx + dx - x).
Expr hfBlock(double x0, double y0, double z0, double dx, double dy, double dz) {
  return rAnd(rAnd((X - x0) * (x0 + dx - X), (Y - y0) * (y0 + dy - Y), 0.0), (Z - z0) * (z0 + dz - Z), 0.0);
}
Expr minMaxBlock(double x0, double y0, double z0, double dx, double dy, double dz) {
  return min(min(min(X - x0, x0 + dx - X), min(Y - y0, y0 + dy - Y)), min(Z - z0, z0 + dz - Z));
}

struct Run {
  double cpu;
  size_t leaves;
};

Run sampleSum(const Expr& slab, bool minMaxOperands, int n) {
  const Expr ball = 0.09 - square(X) - square(Y) - square(Z);
  MinkowskiOptions o;
  o.minMaxOperands = minMaxOperands;
  const Expr sum = minkowskiSum(slab, ball, 3, Bounds{{-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}}, o);
  SampleOptions so;
  so.threads = 1;
  const double t0 = cpuSeconds();
  SampleResult r = sample(Tape::compile(sum, 3), GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, n), so);
  return {cpuSeconds() - t0, r.leaves.size()};
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 48;
  const Expr rSlab = rSubtraction(hfBlock(-1, -1, -0.25, 2, 2, 0.5), hfBlock(-0.2, -0.2, -1, 1.5, 1.5, 2), 0.0);
  const Expr mSlab = min(minMaxBlock(-1, -1, -0.25, 2, 2, 0.5), -minMaxBlock(-0.2, -0.2, -1, 1.5, 1.5, 2));
  const Run base = sampleSum(mSlab, true, n);
  const Run fast = sampleSum(rSlab, true, n);
  const Run slow = sampleSum(rSlab, false, n);
  std::printf("non-convex slab (+) ball, sample %d^3, one thread     CPU s   leaves   vs min/max\n", n);
  std::printf("  written with min/max of half-spaces (baseline)  %8.2f %8zu   1.00x\n", base.cpu, base.leaves);
  std::printf("  hfBlock + '\\' (sqrt R-functions), min/max form  %8.2f %8zu   %.2fx\n", fast.cpu, fast.leaves, fast.cpu / base.cpu);
  std::printf("  hfBlock + '\\', searched as written              %8.2f %8zu   %.2fx\n", slow.cpu, slow.leaves, slow.cpu / base.cpu);
  std::printf("min/max form vs as written: %.1fx faster\n", slow.cpu / fast.cpu);
  return 0;
}
