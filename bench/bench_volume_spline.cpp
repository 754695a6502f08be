// Volume-spline reconstruction of 10^4 surface points (3 * 10^4 centres with the off-surface
// points): fit CPU time and memory, batch and interval evaluation rates, against a baseline
// measured in the same run (the batch rate of the sphere formula x^2 + y^2 + z^2 - 1).
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "bench_timing.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/primitives/volume_spline.h"

using namespace frep;

namespace {

double peakMb() {
  rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;
}

// Batch rate (points per CPU second) of a tape over random points in [-1.2, 1.2]^3.
double batchRate(const Tape& t, double minSeconds) {
  BatchEvaluator<double> be;
  be.reserve(t);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const size_t B = BatchEvaluator<double>::kBatch;
  for (uint32_t k = 0; k < 3; ++k)
    for (size_t i = 0; i < B; ++i) be.in(k)[i] = u(rng);
  size_t points = 0;
  double sink = 0.0;
  const double t0 = bench::cpuSeconds();
  double dt = 0.0;
  while (dt < minSeconds) {
    sink += be.eval(t, B)[0];
    points += B;
    dt = bench::cpuSeconds() - t0;
  }
  if (sink == 12345.678) std::printf(" ");
  return double(points) / dt;
}

}  // namespace

int main(int argc, char** argv) {
  const size_t n = argc > 1 ? size_t(std::atol(argv[1])) : 10000;
  std::vector<Point3> p, nrm, c;
  std::vector<double> v;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (size_t i = 0; i < n; ++i) {  // an ellipsoid with semi-axes 1, 0.8, 0.6 (normals by its gradient)
    const double z = 1.0 - 2.0 * (double(i) + 0.5) / double(n), r = std::sqrt(1.0 - z * z), t = golden * double(i);
    const double x = r * std::cos(t), y = r * std::sin(t);
    p.push_back({x, 0.8 * y, 0.6 * z});
    nrm.push_back({x, y / 0.8, z / 0.6});
  }
  offSurfacePoints(p, nrm, 0.02, c, v);
  const double mem0 = peakMb(), t0 = bench::cpuSeconds();
  auto s = VolumeSpline::fit(c, v);
  const double fitSeconds = bench::cpuSeconds() - t0, mem1 = peakMb();
  std::printf("volume spline: %zu surface points, %zu centres (%zu dense, support radius %.4f)\n", n, c.size(),
              s->numDense(), s->supportRadius());
  std::printf("fit: %.2f s CPU, peak memory %.0f MB (+%.0f MB), max residual at the centres %.2e\n", fitSeconds, mem1,
              mem1 - mem0, s->maxResidual());

  TapePtr spline = Tape::compile(fieldCall(s, Expr::x(0), Expr::x(1), Expr::x(2)), 3);
  TapePtr sphere = Tape::compile(square(Expr::x(0)) + square(Expr::x(1)) + square(Expr::x(2)) - 1.0, 3);
  const double base = batchRate(*sphere, 0.5), rate = batchRate(*spline, 2.0);
  std::printf("batch evaluation: %.3g points/s (sphere formula %.3g points/s, ratio %.2e; %.3g centre terms/s)\n",
              rate, base, rate / base, rate * double(s->numDense()));

  IntervalEvaluator ie;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1.2, 1.1);
  size_t boxes = 0;
  const double t1 = bench::cpuSeconds();
  while (bench::cpuSeconds() - t1 < 1.0) {
    Interval box[3];
    for (auto& b : box) {
      const double lo = u(rng);
      b = Interval(lo, lo + 0.05);
    }
    ie.eval(*spline, box);
    ++boxes;
  }
  std::printf("interval bounds: %.3g boxes/s (0.05-wide boxes)\n", double(boxes) / (bench::cpuSeconds() - t1));
  return 0;
}
