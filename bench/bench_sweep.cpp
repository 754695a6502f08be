// Sweep benchmark (issue 6): a ball of radius r swept along a segment of length L by the
// extremum node (frep::sweep: max over t of the ball moved to P(t), certified interval
// branch-and-bound over t, gap E = half a voxel) against "stamping": the union (max) of N copies
// of the ball at t_i = i / (N - 1), with N chosen so that the stamping error matches the sweep's
// error bound. Both are sampled by frep::sample on the same grid, one thread each; the volume
// (lattice points with f >= 0 times the voxel volume) is compared with the capsule formula
// pi r^2 L + 4/3 pi r^3, and with the exact capsule counted on the same lattice (the lattice's
// own error). Stamping is also run with N doubled until its volume is as close to the exact
// lattice count as the sweep's (the sweep's actual error is far below its certified bound).
// Figures and ratios are measured in the same run; it never fails on time.
//
// Matching the error: the ball's field r - |X - P| is an exact distance, so both results are
// distance-like. The sweep's value is within E of the true sweep (certified). Between two stamps
// Delta = L / (N - 1) apart, the union's surface sags by r - sqrt(r^2 - Delta^2 / 4) ~
// Delta^2 / (8 r); the value error is at most that sag, so N = ceil(L / Delta) + 1 with
// r - sqrt(r^2 - Delta^2 / 4) <= E.
//
// Usage: bench_sweep [--quick]   (--quick: 64^3 only)
#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

#include "bench_timing.h"

using namespace frep;

namespace {

constexpr double kPi = 3.141592653589793;

struct Run {
  double seconds = 0, volume = 0;
  uint64_t bandVoxels = 0;
};

Run runSample(const Expr& model, const GridSpec& g) {
  TapePtr t = Tape::compile(model);
  SampleOptions o;
  o.threads = 1;  // one core on both sides of every ratio
  const double t0 = bench::cpuSeconds();  // both sides run on one thread
  SampleResult res = sample(t, g, o);
  Run r;
  r.seconds = bench::cpuSeconds() - t0;
  r.volume = insideVolume(res);
  r.bandVoxels = res.stats.pointEvals;
  return r;
}

void segment(int res) {
  const double r = 0.3;
  const double p0[3] = {-1.0, -0.3, -0.2}, p1[3] = {1.0, 0.35, 0.25};
  const double d[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const double L = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  // Bounds chosen so that no lattice plane is aligned with the capsule's extremes.
  GridSpec g = GridSpec::fromBounds({-1.4137, -1.4071, -1.4029}, {1.4137, 1.4071, 1.4029}, res);
  const double E = 0.5 * g.voxel;
  const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr ball = r - sqrt(square(X) + square(Y) + square(Z));

  // The sweep: translation P(t) = p0 + t d over t in [0, 1].
  Motion m;
  const Expr t = Expr::x(0);
  for (int a = 0; a < 3; ++a) m.translation.push_back(p0[a] + d[a] * t);
  SearchOptions so;
  so.method = ExtremumMethod::BranchAndBound;
  so.tolerance = E;
  Expr swept = sweep(ball, 3, m, 0.0, 1.0, so);

  // Stamping: N copies, sag <= E.
  const double delta = 2.0 * std::sqrt(r * r - (r - E) * (r - E));
  const int N = int(std::ceil(L / delta)) + 1;
  auto stampsOf = [&](int count) {
    Expr u;
    for (int i = 0; i < count; ++i) {
      const double s = double(i) / double(count - 1);
      Expr b = r - sqrt(square(X - (p0[0] + s * d[0])) + square(Y - (p0[1] + s * d[1])) + square(Z - (p0[2] + s * d[2])));
      u = i == 0 ? b : max(u, b);
    }
    return u;
  };
  Expr stamps = stampsOf(N);
  const double sag = r - std::sqrt(r * r - 0.25 * (L / (N - 1)) * (L / (N - 1)));

  // The exact capsule on the same lattice.
  const double vLattice = latticeVolume(g, [&](const std::array<double, 3>& p) {
    double q[3] = {p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]};
    double s = std::clamp((q[0] * d[0] + q[1] * d[1] + q[2] * d[2]) / (L * L), 0.0, 1.0);
    double e2 = 0;
    for (int a = 0; a < 3; ++a) e2 += (q[a] - s * d[a]) * (q[a] - s * d[a]);
    return e2 <= r * r;
  });
  const double vCapsule = kPi * r * r * L + 4.0 * kPi * r * r * r / 3.0;

  Run sw = runSample(swept, g);
  Run st = runSample(stamps, g);
  std::printf("\n%d^3 (voxel %.4f): ball r %.2f along a segment of length %.4f; error bound E = %.4f\n", res,
              g.voxel, r, L, E);
  std::printf("  capsule formula pi r^2 L + 4/3 pi r^3 = %.5f; exact capsule on this lattice %.5f (%+.3f%%)\n",
              vCapsule, vLattice, 100 * (vLattice - vCapsule) / vCapsule);
  std::printf("  %-36s %9s %12s %10s %12s %12s\n", "method", "cpu s", "band voxels", "volume", "vs formula",
              "vs lattice");
  std::printf("  %-36s %9.3f %12llu %10.5f %+11.3f%% %+11.3f%%\n", "sweep (B&B over t, gap E)", sw.seconds,
              (unsigned long long)sw.bandVoxels, sw.volume, 100 * (sw.volume - vCapsule) / vCapsule,
              100 * (sw.volume - vLattice) / vLattice);
  char name[64];
  std::snprintf(name, sizeof name, "stamping, N = %d (sag %.4f <= E)", N, sag);
  std::printf("  %-36s %9.3f %12llu %10.5f %+11.3f%% %+11.3f%%\n", name, st.seconds,
              (unsigned long long)st.bandVoxels, st.volume, 100 * (st.volume - vCapsule) / vCapsule,
              100 * (st.volume - vLattice) / vLattice);
  std::printf("  ratio stamping / sweep time: %.2fx (at equal error bound)\n", st.seconds / sw.seconds);
  // The sweep's actual error is far below its bound (the value found is the best of the search,
  // the bound is only certified). Stamping at equal *measured* volume error (against the exact
  // capsule on the same lattice): double N until it is as close as the sweep.
  const double sweepErr = std::fabs(sw.volume - vLattice);
  int N2 = N;
  Run st2 = st;
  while (std::fabs(st2.volume - vLattice) > sweepErr && N2 < 8192) {
    N2 *= 2;
    st2 = runSample(stampsOf(N2), g);
  }
  std::snprintf(name, sizeof name, "stamping, N = %d (equal volume error)", N2);
  std::printf("  %-36s %9.3f %12llu %10.5f %+11.3f%% %+11.3f%%\n", name, st2.seconds,
              (unsigned long long)st2.bandVoxels, st2.volume, 100 * (st2.volume - vCapsule) / vCapsule,
              100 * (st2.volume - vLattice) / vLattice);
  std::printf("  ratio stamping / sweep time: %.2fx (at equal measured volume error)\n", st2.seconds / sw.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::printf("Sweep (extremum node, B&B over t) vs stamping N copies at equal error bound, single thread\n");
  segment(64);
  if (!quick) {
    segment(128);
    segment(256);
  }
  return 0;
}
