// Issue 11's figures for a 100k-triangle mesh primitive (frMesh's MeshField): sampling at 256^3
// as a fraction of dense evaluation (point evaluations and time), and exact signed-distance
// queries per second per core against OpenVDB's tools::meshToLevelSet on the same mesh and grid
// (narrow band of 3 voxels, one thread each). The mesh: a torus of 224 x 224 quads (100352
// triangles), closed and consistently oriented.
//   build/bench/bench_hybrid_mesh [cells]
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/geometry/distance_fields.h"
#include "frep/sampling/sample.h"

using namespace frep;
using Clock = std::chrono::steady_clock;

static double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 224;
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
  return sink == 12345.678 ? 1 : 0;
}
