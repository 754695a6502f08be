// Issue 11's figures for a 100k-triangle mesh primitive (frMesh's MeshField): sampling at 256^3
// as a fraction of dense evaluation (point evaluations and time), and exact signed-distance
// queries per second per core against OpenVDB's tools::meshToLevelSet on the same mesh and grid
// (narrow band of 3 voxels, one thread each). The mesh: a torus of 224 x 224 quads (100352
// triangles), closed and consistently oriented. The sampling fraction is set against the band the
// sampler must keep: lattice points within 3 voxels (Chebyshev) of a sign change, counted from
// the sampled signs. Last, frMinkowski(x, cube mesh, ball) both ways at the same grid: the exact
// offset path (minkowski_algebra/distance_offset.h) and the certified search it replaces.
//   build/bin/bench_hybrid_mesh [cells] [minkowski res]
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/basic_set.h"
#include "frep/minkowski_algebra/distance_offset.h"
#include "frep/minkowski_algebra/reduction.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/sampling/sample.h"

using namespace frep;
using Clock = std::chrono::steady_clock;

static double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Lattice points whose (2 band + 1)^3 neighbourhood (clipped to the grid) holds both signs: the
// points a band of `band` voxels around the sampled zero set must keep.
static uint64_t bandPoints(const SampleResult& s, int band) {
  const auto& d = s.grid.dims;
  const size_t nx = size_t(d[0]), ny = size_t(d[1]), nz = size_t(d[2]);
  std::vector<int8_t> in(nx * ny * nz, 0);  // 1 inside, 0 outside
  auto at = [&](size_t i, size_t j, size_t k) { return (i * ny + j) * nz + k; };
  for (const Tile& t : s.tiles)
    if (t.inside)
      for (int i = t.origin[0]; i < std::min(t.origin[0] + t.size, d[0]); ++i)
        for (int j = t.origin[1]; j < std::min(t.origin[1] + t.size, d[1]); ++j)
          for (int k = t.origin[2]; k < std::min(t.origin[2] + t.size, d[2]); ++k) in[at(i, j, k)] = 1;
  for (const LeafBlock& l : s.leaves)
    for (int o = 0; o < kLeafVoxels; ++o) {
      const int i = l.origin[0] + (o >> 6), j = l.origin[1] + ((o >> 3) & 7), k = l.origin[2] + (o & 7);
      if (i < d[0] && j < d[1] && k < d[2]) in[at(i, j, k)] = l.values[o] >= 0;
    }
  // Separable max filters of "inside" and of "outside" over the cube of half-width band.
  auto dilate = [&](std::vector<int8_t> v) {
    const size_t n[3] = {nx, ny, nz}, stride[3] = {ny * nz, nz, 1};
    for (int a = 0; a < 3; ++a) {
      std::vector<int8_t> out(v.size(), 0);
      for (size_t idx = 0; idx < v.size(); ++idx) {
        if (!v[idx]) continue;
        const long c = long((idx / stride[a]) % n[a]);
        for (long q = std::max(0L, c - band); q <= std::min(long(n[a]) - 1, c + band); ++q)
          out[idx + (q - c) * long(stride[a])] = 1;
      }
      v.swap(out);
    }
    return v;
  };
  std::vector<int8_t> out(in.size());
  for (size_t i = 0; i < in.size(); ++i) out[i] = !in[i];
  const std::vector<int8_t> a = dilate(in), b = dilate(out);
  uint64_t count = 0;
  for (size_t i = 0; i < a.size(); ++i) count += a[i] && b[i];
  return count;
}

// frMinkowski(x, unit cube mesh, ball r 0.25): exact offset vs the certified search (the ball
// as a formula, so that nothing recognises it), sampled on one grid, one thread each.
static void minkowskiTiming(int res) {
  const double C[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const uint32_t T[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  for (auto& p : C) xyz.insert(xyz.end(), p, p + 3);
  for (auto& t : T) tris.insert(tris.end(), t, t + 3);
  const double r = 0.25;
  Expr cube = fieldCall(std::make_shared<MeshField>(xyz, tris, "cube"), Expr::x(0), Expr::x(1), Expr::x(2));
  minkowski::Shape ball;
  ball.size[0] = r;
  const minkowski::Sum bs = minkowski::sumOf(ball);
  const minkowski::Reduction red = minkowski::reduce(bs);
  Expr ballField = minkowski::unionExpr(red, {Expr::x(0), Expr::x(1), Expr::x(2)});
  minkowski::ExactTerm term;
  term.sum = bs;
  minkowski::registerExact(ballField, term);  // what frBall does
  Expr fast;
  if (!minkowski::distanceBallSum(cube, ballField, 3, &fast)) {
    std::printf("minkowski: the exact path did not apply\n");
    return;
  }
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr formulaBall = r * r - square(X) - square(Y) - square(Z);
  Expr searched = minkowskiSum(cube, formulaBall, 3, Bounds{{-r, -r, -r}, {r, r, r}});
  const GridSpec g = GridSpec::fromBounds({-0.4, -0.4, -0.4}, {1.4, 1.4, 1.4}, res);
  SampleOptions so;
  so.threads = 1;
  auto t0 = Clock::now();
  SampleResult a = sample(Tape::compile(fast, 3), g, so);
  const double tFast = seconds(t0);
  t0 = Clock::now();
  SampleResult b = sample(Tape::compile(searched, 3), g, so);
  const double tSearch = seconds(t0);
  const double steiner = 1 + 6 * r + 3 * M_PI * r * r + 4.0 / 3.0 * M_PI * r * r * r;
  std::printf("frMinkowski(cube mesh, ball 0.25) sampled at %d^3, 1 thread: exact offset %.4f s (lattice volume %.4f),"
              " certified search %.2f s (lattice volume %.4f), Steiner %.4f; ratio search/exact %.0fx\n",
              res, tFast, insideVolume(a), tSearch, insideVolume(b), steiner, tSearch / tFast);
}

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 224;
  const int minkowskiRes = argc > 2 ? std::atoi(argv[2]) : 16;
  const double R = 0.6, r = 0.25;
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / n;
      xyz.insert(xyz.end(), {(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  auto id = [&](int i, int j) { return uint32_t((i % n) * n + (j % n)); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      tris.insert(tris.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.insert(tris.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  auto t0 = Clock::now();
  auto field = std::make_shared<MeshField>(xyz, tris, "torus");
  std::printf("mesh: %zu triangles, closed %d, BVH build %.3f s\n", field->numTriangles(), int(field->check().closed()),
              seconds(t0));

  // Sampling at 256^3, one thread.
  const GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 256);
  TapePtr tape = Tape::compile(fieldCall(field, Expr::x(0), Expr::x(1), Expr::x(2)), 3);
  SampleOptions so;
  so.threads = 1;
  t0 = Clock::now();
  SampleResult s = sample(tape, g, so);
  const double tSparse = seconds(t0);
  // Dense cost: every grid point's exact distance; timed on 2 planes of points and scaled.
  const uint64_t dense = uint64_t(g.dims[0]) * g.dims[1] * g.dims[2];
  PointEvaluator pe;
  t0 = Clock::now();
  double sink = 0;
  uint64_t counted = 0;
  for (int k : {g.dims[2] / 2, g.dims[2] / 3})
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const double p[3] = {g.origin[0] + i * g.voxel, g.origin[1] + j * g.voxel, g.origin[2] + k * g.voxel};
        sink += pe.eval(*tape, p);
        ++counted;
      }
  const double tDense = seconds(t0) * double(dense) / double(counted);
  std::printf("sample 256^3 (1 thread): %.3f s, %llu point evals = %.2f%% of dense (%llu), interval evals %llu;"
              " dense (estimated from %llu points) %.1f s: time %.2f%% of dense\n",
              tSparse, (unsigned long long)s.stats.pointEvals, 100.0 * double(s.stats.pointEvals) / double(dense),
              (unsigned long long)dense, (unsigned long long)s.stats.intervalEvals, (unsigned long long)counted, tDense,
              100.0 * tSparse / tDense);

  // The band the sampler must keep (the contract: every point within 3 voxels of a zero).
  const uint64_t band = bandPoints(s, so.bandVoxels);
  std::printf("band to keep (lattice points within %d voxels, Chebyshev, of a sign change): %llu = %.2f%% of dense;"
              " evaluations / band %.2f\n",
              so.bandVoxels, (unsigned long long)band, 100.0 * double(band) / double(dense),
              double(s.stats.pointEvals) / double(band));

  // Narrow-band queries per second per core: exact signed distance at points within 3 voxels.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uni(0, 1);
  std::vector<std::array<double, 3>> pts(200000);
  for (auto& p : pts) {
    const double u = 2 * M_PI * uni(rng), v = 2 * M_PI * uni(rng), d = r + (2 * uni(rng) - 1) * 3 * g.voxel;
    p = {(R + d * std::cos(v)) * std::cos(u), (R + d * std::cos(v)) * std::sin(u), d * std::sin(v)};
  }
  t0 = Clock::now();
  for (const auto& p : pts) sink += field->value(p.data());
  const double qps = double(pts.size()) / seconds(t0);

  // OpenVDB meshToLevelSet on the same mesh and voxel, band 3 voxels each side, one thread.
  openvdb::initialize();
  std::vector<openvdb::Vec3s> vpts;
  std::vector<openvdb::Vec3I> vtris;
  for (size_t i = 0; i < xyz.size(); i += 3)
    vpts.emplace_back(float(xyz[i]), float(xyz[i + 1]), float(xyz[i + 2]));
  for (size_t i = 0; i < tris.size(); i += 3) vtris.emplace_back(tris[i], tris[i + 1], tris[i + 2]);
  auto xf = openvdb::math::Transform::createLinearTransform(g.voxel);
  openvdb::FloatGrid::Ptr ls;
  double tVdb;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    t0 = Clock::now();
    ls = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, vpts, vtris, 3.0f);
    tVdb = seconds(t0);
  }
  const double voxels = double(ls->activeVoxelCount());
  std::printf("narrow band, 1 thread: exact MeshField %.3g queries/s; OpenVDB meshToLevelSet %.0f active voxels in"
              " %.3f s = %.3g voxels/s (approximate, float); ratio exact/OpenVDB %.2f\n",
              qps, voxels, tVdb, voxels / tVdb, qps / (voxels / tVdb));
  // The same band through frep's sparse sampler (exact): voxels stored per second.
  std::printf("frep sparse sample of the band: %.3g point evals/s\n", double(s.stats.pointEvals) / tSparse);
  minkowskiTiming(minkowskiRes);
  return sink == 12345.678 ? 1 : 0;
}
