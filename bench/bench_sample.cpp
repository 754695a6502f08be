// Sparse sampling cost: point evaluations as a fraction of a dense grid, for the sphere and the
// ~100-node CSG part, at 128^3 and 256^3 and several band widths; plus wall time of the sparse
// sampler against a dense batch evaluation of the same grid (baseline measured in this run).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>

#include "bench_models.h"
#include "frep/evaluators/eval.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

// Voxels a perfect band sampler must evaluate: those within `band` (Chebyshev) of both ends of a
// sign change between grid neighbours (the sampler's guarantee), from a dense evaluation.
uint64_t idealBand(const TapePtr& tape, const GridSpec& g, int band) {
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  auto at = [&](int i, int j, int k) { return (size_t(i) * ny + j) * nz + k; };
  std::vector<uint8_t> inside(size_t(nx) * ny * nz), mark(inside.size(), 0);
  PointEvaluator pe;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        auto p = g.world(i, j, k);
        inside[at(i, j, k)] = pe.eval(*tape, p.data()) >= 0;
      }
  // Seeds: voxels with a neighbour of the other sign; then a separable Chebyshev dilation.
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        uint8_t s = inside[at(i, j, k)];
        if ((i + 1 < nx && inside[at(i + 1, j, k)] != s) || (j + 1 < ny && inside[at(i, j + 1, k)] != s) ||
            (k + 1 < nz && inside[at(i, j, k + 1)] != s) || (i > 0 && inside[at(i - 1, j, k)] != s) ||
            (j > 0 && inside[at(i, j - 1, k)] != s) || (k > 0 && inside[at(i, j, k - 1)] != s))
          mark[at(i, j, k)] = 1;
      }
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<uint8_t> next(mark.size(), 0);
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        for (int k = 0; k < nz; ++k) {
          if (!mark[at(i, j, k)]) continue;
          for (int d = -(band - 1); d <= band - 1; ++d) {
            int q[3] = {i, j, k};
            q[axis] += d;
            if (q[axis] < 0 || q[axis] >= g.dims[axis]) continue;
            next[at(q[0], q[1], q[2])] = 1;
          }
        }
    mark.swap(next);
  }
  uint64_t n = 0;
  for (uint8_t m : mark) n += m;
  return n;
}

double denseSeconds(const TapePtr& tape, const GridSpec& g) {
  auto t0 = std::chrono::steady_clock::now();
  BatchEvaluator<double> be;
  be.reserve(*tape);
  double sink = 0;
  const size_t B = BatchEvaluator<double>::kBatch;
  for (int i = 0; i < g.dims[0]; ++i)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int k0 = 0; k0 < g.dims[2]; k0 += int(B)) {
        size_t n = std::min<size_t>(B, size_t(g.dims[2] - k0));
        for (size_t k = 0; k < n; ++k) {
          auto p = g.world(i, j, k0 + int(k));
          be.in(0)[k] = p[0];
          be.in(1)[k] = p[1];
          be.in(2)[k] = p[2];
        }
        sink += be.eval(*tape, n)[0];
      }
  benchmark::DoNotOptimize(sink);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void report(const char* name, const Expr& model, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  auto tape = Tape::compile(model, 3);
  std::printf("\n%s: %zu tape instructions\n", name, tape->size());
  std::printf("  %5s %5s %5s %12s %12s %9s %9s %10s %10s %8s %9s\n", "res", "band", "block", "point evals", "dense",
              "fraction", "floor", "sparse s", "dense s", "speedup", "avg tape");
  for (int res : {128, 256}) {
    GridSpec g = GridSpec::fromBounds(lo, hi, res);
    double dense = denseSeconds(tape, g);
    // block: SampleOptions::leafBlock, 2 (raw store, Python) or 4 (frep sample's distance stores)
    for (int band : {1, 2, 3})
      for (int block : {2, 4}) {
        SampleOptions o;
        o.bandVoxels = band;
        o.leafBlock = block;
        o.threads = 1;  // single core on both sides of the ratio
        auto t0 = std::chrono::steady_clock::now();
        SampleResult r = sample(tape, g, o);
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        double avgTape = r.stats.tapeBatches ? double(r.stats.tapeInstrs) / double(r.stats.tapeBatches) : 0;
        // floor: the fraction a perfect sampler with the same guarantee needs (a voxel within
        // band - 1 of a sign-change voxel is within band of both ends of that change)
        double floorFraction = double(idealBand(tape, g, band)) / double(r.stats.denseEvals);
        std::printf("  %5d %5d %5d %12llu %12llu %8.2f%% %8.2f%% %10.3f %10.3f %7.1fx %9.1f\n", res, band, block,
                    (unsigned long long)r.stats.pointEvals, (unsigned long long)r.stats.denseEvals,
                    100.0 * double(r.stats.pointEvals) / double(r.stats.denseEvals), 100.0 * floorFraction, s, dense,
                    dense / s, avgTape);
      }
  }
}

void BM_SampleCsg256(benchmark::State& state) {
  auto tape = Tape::compile(bench::csgModel(), 3);
  GridSpec g = GridSpec::fromBounds(bench::kCsgLo, bench::kCsgHi, 256);
  for (auto _ : state) {
    SampleResult r = sample(tape, g);
    benchmark::DoNotOptimize(r.leaves.data());
  }
}
BENCHMARK(BM_SampleCsg256)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

int main(int argc, char** argv) {
  report("sphere r=0.8 in [-1,1]^3", bench::sphereModel(), bench::kSphereLo, bench::kSphereHi);
  report("CSG part (111 nodes) in [-2.2,2.2]^3", bench::csgModel(), bench::kCsgLo, bench::kCsgHi);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
