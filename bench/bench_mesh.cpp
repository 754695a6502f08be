// Meshing throughput and accuracy: frepfarm's mesher (core meshGrid, marching tetrahedra on the
// Kuhn grid, vertices by root finding on the model) against OpenVDB's tools::volumeToMesh on the
// same model sampled by frep::sample (band 1) and converted to a FloatGrid by the same code as
// `frep sample` (frep/io/vdb_grid.h), measured in this run; plus the farm master's peak memory for
// `frep mesh` of the same model (the frep binary run as a child, its report's peak_rss_bytes).
//
// Model (libfive's benchmark shape, here defined concretely):
//   f = min(1 - (x^2 + y^2 + z^2), 0.3 - |g(8x, 8y, 8z)|),  g(x, y, z) = sin x cos y + sin y cos z + sin z cos x
// the unit ball intersected with a gyroid sheet (|g| < 0.3, period 2 pi / 8 = 0.785), over the
// box [-1.1, 1.1]^3 with N grid points per axis (N = 256, 512; --quick: 128).
//
// Throughput is in dense-voxel-equivalents per second: the N^3 points of the full grid divided
// by the wall time, also divided by the threads used (per core). Triangle counts count a quad as
// two triangles. Hausdorff distances (in voxels) to the true surface {f = 0}:
//   mesh -> surface: every vertex and every triangle's centroid projected on the surface by
//     Newton steps x -= f grad f / |grad f|^2 (the gradient evaluator; a bracketing search along
//     the gradient where Newton does not converge); the distance moved bounds the distance;
//   surface -> mesh: surface points made by projecting the grid points of a second grid (spacing
//     1.5 voxels, offset 0.37 voxel, band 1 of frep::sample) on the surface, each measured to the
//     nearest triangle exactly (point-triangle distance, triangles binned in 2-voxel cells).
// Each row also gives the CPU seconds (user + system) it took and the throughput per CPU second,
// steadier than wall time on a shared machine. Never fails on time: it prints figures only. Options: --quick, --sizes 256,512, --no-farm.
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/sampling/sample.h"
#include "frep/expressions/tape.h"
#include "frep/io/vdb_grid.h"
#include "bench_models.h"

using namespace frep;

namespace {

using Vec3 = std::array<double, 3>;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// CPU seconds (user + system) of this process so far: on a shared machine the per-core figure
// from CPU time is steadier than the one from wall time (other jobs take turns on the cores).
double cpuSeconds() {
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

using bench::gyroidModel;
const char* kGyroidHf =
    "-- bench_mesh: the unit ball intersected with a gyroid sheet (period 2 pi / 8)\n"
    "my_model(x[3], a[1])\n"
    "{\n"
    "  g = sin(8*x[1])*cos(8*x[2]) + sin(8*x[2])*cos(8*x[3]) + sin(8*x[3])*cos(8*x[1]);\n"
    "  my_model = min(1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3], 0.3 - abs(g));\n"
    "}\n";
constexpr double kLo = -1.1, kHi = 1.1;

// A triangle soup view of a mesh: positions and triangles (quads split along 0-2).
struct Soup {
  std::vector<Vec3> p;
  std::vector<std::array<uint32_t, 3>> t;
};

// ---- distances ---------------------------------------------------------------------------

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Squared distance from p to triangle abc: the closest point is found by the region of p's
// projection (a vertex, an edge, or the face), from barycentric tests on dot products.
double pointTriangle2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto dist2 = [&](const Vec3& q) {
    Vec3 d = sub(p, q);
    return dot(d, d);
  };
  if (d1 <= 0 && d2 <= 0) return dist2(a);
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return dist2(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return dist2({a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]});
  }
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return dist2(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return dist2({a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return dist2({b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])});
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return dist2({a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

// Projection of p on {f = 0}: Newton steps along the gradient; where they do not converge
// within 3 voxels, a sign change is bracketed along the initial gradient and bisected.
// Returns the distance moved (world units), or -1 when no surface point was found.
struct Projector {
  GradientEvaluator ge;
  PointEvaluator pe;
  double project(const Tape& tape, const Vec3& p0, double voxel, Vec3* foot) {
    Vec3 x = p0;
    double g[3];
    for (int it = 0; it < 40; ++it) {
      const double f = ge.eval(tape, x.data(), g);
      const double gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
      if (!(gg > 0) || !std::isfinite(f)) break;
      const double s = f / gg;
      for (int a = 0; a < 3; ++a) x[a] -= s * g[a];
      const double step = std::abs(s) * std::sqrt(gg);
      Vec3 d = sub(x, p0);
      if (dot(d, d) > 9 * voxel * voxel) break;
      if (step < 1e-9 * voxel) {
        if (foot) *foot = x;
        return std::sqrt(dot(d, d));
      }
    }
    // Bracketing along the initial gradient, steps of 0.05 voxel up to 3 voxels each way.
    const double f0 = ge.eval(tape, p0.data(), g);
    double gl = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(gl > 0)) return -1;
    const Vec3 dir{g[0] / gl, g[1] / gl, g[2] / gl};
    auto at = [&](double t) {
      Vec3 q{p0[0] + t * dir[0], p0[1] + t * dir[1], p0[2] + t * dir[2]};
      return pe.eval(tape, q.data());
    };
    for (int k = 1; k <= 60; ++k) {
      for (int sgn : {-1, 1}) {
        double t1 = sgn * k * 0.05 * voxel, t0 = sgn * (k - 1) * 0.05 * voxel;
        double fa = k == 1 ? f0 : at(t0), fb = at(t1);
        if ((fa >= 0) != (fb >= 0)) {
          for (int b = 0; b < 60; ++b) {
            double tm = 0.5 * (t0 + t1), fm = at(tm);
            if ((fm >= 0) == (fa >= 0)) {
              t0 = tm;
              fa = fm;
            } else {
              t1 = tm;
            }
          }
          const double t = 0.5 * (t0 + t1);
          if (foot) *foot = {p0[0] + t * dir[0], p0[1] + t * dir[1], p0[2] + t * dir[2]};
          return std::abs(t);
        }
      }
    }
    return -1;
  }
};

struct Stat {
  double max = 0, sum = 0;
  uint64_t n = 0, failed = 0;
  Vec3 at{0, 0, 0};  // where the maximum is
  void add(double d, const Vec3& p) {
    if (d < 0) {
      ++failed;
      return;
    }
    if (d > max) at = p;
    max = std::max(max, d);
    sum += d;
    ++n;
  }
  void merge(const Stat& o) {
    if (o.max > max) at = o.at;
    max = std::max(max, o.max);
    sum += o.sum;
    n += o.n;
    failed += o.failed;
  }
  double mean() const { return n ? sum / double(n) : 0.0; }
};

// mesh -> surface: vertices and centroids projected on the surface (voxels).
Stat meshToSurface(const TapePtr& tape, const Soup& m, double voxel) {
  tbb::enumerable_thread_specific<Projector> proj;
  tbb::enumerable_thread_specific<Stat> stats;
  const size_t nv = m.p.size(), n = nv + m.t.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    Projector& pr = proj.local();
    Stat& st = stats.local();
    for (size_t i = r.begin(); i < r.end(); ++i) {
      Vec3 q;
      if (i < nv) {
        q = m.p[i];
      } else {
        const auto& t = m.t[i - nv];
        for (int a = 0; a < 3; ++a) q[a] = (m.p[t[0]][a] + m.p[t[1]][a] + m.p[t[2]][a]) / 3.0;
      }
      double d = pr.project(*tape, q, voxel, nullptr);
      st.add(d < 0 ? d : d / voxel, q);
    }
  });
  Stat total;
  for (const Stat& s : stats) total.merge(s);
  return total;
}

// Points on the surface, from a second grid (spacing 1.5 voxels, offset 0.37 voxel).
std::vector<Vec3> surfacePoints(const TapePtr& tape, const GridSpec& grid) {
  GridSpec g2;
  g2.voxel = 1.5 * grid.voxel;
  for (int a = 0; a < 3; ++a) {
    g2.origin[a] = grid.origin[a] + 0.37 * grid.voxel;
    g2.dims[a] = int32_t((double(grid.dims[a] - 1) * grid.voxel - 0.37 * grid.voxel) / g2.voxel) + 1;
  }
  SampleOptions so;
  so.bandVoxels = 1;
  SampleResult s = sample(tape, g2, so);
  std::vector<Vec3> seeds;
  for (const LeafBlock& l : s.leaves)
    for (int n = 0; n < kLeafVoxels; ++n)
      if (l.isActive(n)) seeds.push_back(g2.world(l.origin[0] + (n >> 6), l.origin[1] + ((n >> 3) & 7), l.origin[2] + (n & 7)));
  std::vector<Vec3> feet(seeds.size());
  std::vector<uint8_t> ok(seeds.size(), 0);
  tbb::enumerable_thread_specific<Projector> proj;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, seeds.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    Projector& pr = proj.local();
    for (size_t i = r.begin(); i < r.end(); ++i) {
      double d = pr.project(*tape, seeds[i], grid.voxel, &feet[i]);
      // Keep feet inside the meshed box (the mesh is open at the box, the surface is not).
      bool inBox = true;
      for (int a = 0; a < 3; ++a)
        inBox = inBox && feet[i][a] >= grid.origin[a] && feet[i][a] <= grid.origin[a] + (grid.dims[a] - 1) * grid.voxel;
      ok[i] = d >= 0 && d <= g2.voxel && inBox;
    }
  });
  std::vector<Vec3> out;
  for (size_t i = 0; i < seeds.size(); ++i)
    if (ok[i]) out.push_back(feet[i]);
  return out;
}

// surface -> mesh: exact distance from each surface point to the nearest triangle (voxels).
Stat surfaceToMesh(const std::vector<Vec3>& pts, const Soup& m, const GridSpec& grid) {
  const double h = 2 * grid.voxel;
  Vec3 lo{1e300, 1e300, 1e300};
  std::array<int64_t, 3> nb{};
  for (const Vec3& p : m.p)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]);
  Vec3 hi{-1e300, -1e300, -1e300};
  for (const Vec3& p : m.p)
    for (int a = 0; a < 3; ++a) hi[a] = std::max(hi[a], p[a]);
  for (int a = 0; a < 3; ++a) nb[a] = int64_t((hi[a] - lo[a]) / h) + 1;
  auto cellOf = [&](double v, int a) { return std::min<int64_t>(std::max<int64_t>(int64_t(std::floor((v - lo[a]) / h)), 0), nb[a] - 1); };
  auto binIndex = [&](int64_t i, int64_t j, int64_t k) { return size_t((i * nb[1] + j) * nb[2] + k); };
  const size_t nbins = size_t(nb[0] * nb[1] * nb[2]);
  std::vector<uint32_t> start(nbins + 1, 0);
  auto forBins = [&](size_t t, auto&& fn) {
    int64_t b0[3], b1[3];
    for (int a = 0; a < 3; ++a) {
      double mn = std::min({m.p[m.t[t][0]][a], m.p[m.t[t][1]][a], m.p[m.t[t][2]][a]});
      double mx = std::max({m.p[m.t[t][0]][a], m.p[m.t[t][1]][a], m.p[m.t[t][2]][a]});
      b0[a] = cellOf(mn, a);
      b1[a] = cellOf(mx, a);
    }
    for (int64_t i = b0[0]; i <= b1[0]; ++i)
      for (int64_t j = b0[1]; j <= b1[1]; ++j)
        for (int64_t k = b0[2]; k <= b1[2]; ++k) fn(binIndex(i, j, k));
  };
  for (size_t t = 0; t < m.t.size(); ++t) forBins(t, [&](size_t b) { ++start[b + 1]; });
  for (size_t b = 0; b < nbins; ++b) start[b + 1] += start[b];
  std::vector<uint32_t> ids(start[nbins]), fill(start.begin(), start.end() - 1);
  for (size_t t = 0; t < m.t.size(); ++t) forBins(t, [&](size_t b) { ids[fill[b]++] = uint32_t(t); });
  std::vector<uint32_t>().swap(fill);

  tbb::enumerable_thread_specific<Stat> stats;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pts.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    Stat& st = stats.local();
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const Vec3& p = pts[i];
      const int64_t c[3] = {cellOf(p[0], 0), cellOf(p[1], 1), cellOf(p[2], 2)};
      double best2 = 1e300;
      int64_t prev = -1;
      for (int64_t rad = 1;; ++rad) {
        for (int64_t x = c[0] - rad; x <= c[0] + rad; ++x)
          for (int64_t y = c[1] - rad; y <= c[1] + rad; ++y)
            for (int64_t z = c[2] - rad; z <= c[2] + rad; ++z) {
              if (x < 0 || y < 0 || z < 0 || x >= nb[0] || y >= nb[1] || z >= nb[2]) continue;
              if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) <= prev) continue;
              const size_t b = binIndex(x, y, z);
              for (uint32_t k = start[b]; k < start[b + 1]; ++k) {
                const auto& t = m.t[ids[k]];
                best2 = std::min(best2, pointTriangle2(p, m.p[t[0]], m.p[t[1]], m.p[t[2]]));
              }
            }
        prev = rad;
        // Bins farther than rad from p's bin are at least rad * h away.
        if (best2 <= double(rad) * h * double(rad) * h || rad > std::max({nb[0], nb[1], nb[2]})) break;
      }
      st.add(std::sqrt(best2) / grid.voxel, p);
    }
  });
  Stat total;
  for (const Stat& s : stats) total.merge(s);
  return total;
}

// ---- the runs ----------------------------------------------------------------------------

struct Row {
  std::string name;
  int threads;
  double seconds, cpu;
  uint64_t triangles;
};

void printRow(const Row& r, double dense) {
  const double rate = dense / r.seconds;
  std::printf("  %-44s %2d thr %8.3f s %8.2f M/s %7.2f M/s/core | cpu %7.3f s %7.2f M/cpu-s | %10llu tris\n",
              r.name.c_str(), r.threads, r.seconds, rate / 1e6, rate / 1e6 / r.threads, r.cpu, dense / r.cpu / 1e6,
              (unsigned long long)r.triangles);
}

void printHausdorff(const char* name, const Stat& ms, const Stat& sm, size_t surfPts) {
  std::printf("  %-22s mesh->surface max %.4f mean %.4f (%llu pts%s)  surface->mesh max %.4f mean %.4f (%zu pts)  "
              "Hausdorff %.4f voxel\n",
              name, ms.max, ms.mean(), (unsigned long long)ms.n,
              ms.failed ? (", " + std::to_string(ms.failed) + " unprojected").c_str() : "", sm.max, sm.mean(), surfPts,
              std::max(ms.max, sm.max));
  std::printf("  %-22s (maxima at (%.4f, %.4f, %.4f), |x| %.4f, and at (%.4f, %.4f, %.4f), |x| %.4f)\n", "",
              ms.at[0], ms.at[1], ms.at[2], std::sqrt(dot(ms.at, ms.at)), sm.at[0], sm.at[1], sm.at[2],
              std::sqrt(dot(sm.at, sm.at)));
}

Soup soupOf(const Mesh& m) {
  Soup s;
  s.p = m.positions;
  s.t = m.triangles;
  return s;
}

Soup soupOf(const std::vector<openvdb::Vec3s>& pts, const std::vector<openvdb::Vec4I>& quads) {
  Soup s;
  s.p.reserve(pts.size());
  for (const auto& p : pts) s.p.push_back({double(p[0]), double(p[1]), double(p[2])});
  s.t.reserve(quads.size() * 2);
  for (const auto& q : quads) {
    s.t.push_back({q[0], q[1], q[2]});
    s.t.push_back({q[0], q[2], q[3]});
  }
  return s;
}

uint64_t fileSize(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? uint64_t(st.st_size) : 0;
}

uint64_t jsonNumber(const std::string& json, const std::string& key) {
  size_t at = json.find("\"" + key + "\"");
  if (at == std::string::npos) return 0;
  at = json.find(':', at);
  return std::strtoull(json.c_str() + at + 1, nullptr, 10);
}

// `frep mesh` of the model on the farm (the embedded default: local workers), as a user runs it.
void farmRun(int n, const std::string& dir) {
  const std::string model = dir + "/gyroid.hf", out = dir + "/gyroid.ply";
  std::ofstream(model) << kGyroidHf;
  const std::string cmd = std::string("'") + FREP_BINARY + "' mesh '" + model + "' -b " + std::to_string(kLo) + "," +
                          std::to_string(kHi) + " --res " + std::to_string(n) + " -O '" + out +
                          "' --no-progress --log-level warn > '" + dir + "/out.txt' 2>&1";
  auto t0 = Clock::now();
  int rc = std::system(cmd.c_str());
  double secs = seconds(t0);
  if (rc != 0) {
    std::printf("  frep mesh --res %d failed (status %d); see %s/out.txt\n", n, rc, dir.c_str());
    return;
  }
  std::stringstream js;
  js << std::ifstream(out + ".report.json").rdbuf();
  const uint64_t rss = jsonNumber(js.str(), "peak_rss_bytes"), tris = jsonNumber(js.str(), "triangles"),
                 verts = jsonNumber(js.str(), "vertices");
  const uint64_t bytes = fileSize(out);
  const uint64_t meshBytes = verts * (3 * 8 * 2 + 8) + tris * 12;  // the merged Mesh in memory
  std::printf("  frep mesh --res %-4d %6.2f s: %10llu vertices %10llu triangles, PLY %8.1f MB; master peak RSS %8.1f MB"
              " = %.2f x PLY bytes = %.2f x in-memory Mesh (%.1f MB), %.1f bytes/triangle\n",
              n, secs, (unsigned long long)verts, (unsigned long long)tris, bytes / 1e6, rss / 1e6,
              bytes ? double(rss) / double(bytes) : 0.0, meshBytes ? double(rss) / double(meshBytes) : 0.0,
              meshBytes / 1e6, tris ? double(rss) / double(tris) : 0.0);
  std::remove(out.c_str());
  std::remove((out + ".report.json").c_str());
}

void runSize(const TapePtr& tape, int n, int cores) {
  GridSpec grid = GridSpec::fromBounds({kLo, kLo, kLo}, {kHi, kHi, kHi}, n);
  const double dense = double(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  std::printf("\n== %dx%dx%d points, voxel %.6g, %.4g M dense voxel-equivalents ==\n", grid.dims[0], grid.dims[1],
              grid.dims[2], grid.voxel, dense / 1e6);
  std::vector<Row> rows;

  // frepfarm: meshGrid in-process, one region (the farm's workers run the same meshRegion).
  Mesh ours;
  for (int threads : {1, cores}) {
    MeshOptions mo;
    mo.threads = threads;
    auto t0 = Clock::now();
    const double c0 = cpuSeconds();
    Mesh m = meshGrid(tape, grid, mo, 0);
    rows.push_back({"frepfarm meshGrid (Kuhn tetrahedra, roots)", threads, seconds(t0), cpuSeconds() - c0,
                    m.triangles.size()});
    if (threads == cores || cores == 1) ours = std::move(m);
    if (cores == 1) break;
  }

  // OpenVDB: frep::sample (band 1) -> FloatGrid (frep sample's converter) -> volumeToMesh.
  std::vector<openvdb::Vec3s> vpts;
  std::vector<openvdb::Vec4I> vquads;
  for (int threads : {1, cores}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    SampleOptions so;
    so.bandVoxels = 1;
    so.threads = threads;
    auto t0 = Clock::now();
    const double c0 = cpuSeconds();
    SampleResult s = sample(tape, grid, so);
    const double tSample = seconds(t0);
    auto t1 = Clock::now();
    openvdb::FloatGrid::Ptr vdb = frep::io::levelSetGrid(s);
    const double tConvert = seconds(t1);
    const double c2 = cpuSeconds();
    std::vector<LeafBlock>().swap(s.leaves);
    std::vector<openvdb::Vec3s> pts;
    std::vector<openvdb::Vec4I> quads;
    auto t2 = Clock::now();
    openvdb::tools::volumeToMesh(*vdb, pts, quads, 0.0);
    const double tMesh = seconds(t2);
    const double c3 = cpuSeconds();
    const uint64_t tris = 2 * quads.size();
    rows.push_back({"OpenVDB volumeToMesh alone", threads, tMesh, c3 - c2, tris});
    rows.push_back({"frep::sample + FloatGrid + volumeToMesh", threads, tSample + tConvert + tMesh, c3 - c0, tris});
    std::printf("  (OpenVDB path, %d thr: sample %.3f s, to FloatGrid %.3f s, volumeToMesh %.3f s; %zu points, %zu quads)\n",
                threads, tSample, tConvert, tMesh, pts.size(), quads.size());
    if (threads == cores || cores == 1) {
      vpts.swap(pts);
      vquads.swap(quads);
    }
    if (cores == 1) break;
  }
  for (const Row& r : rows) printRow(r, dense);
  std::printf("  frepfarm mesh: %zu vertices, %zu triangles; cells examined %llu, crossed %llu; evaluations: grid "
              "points %llu, root finding %llu, gradients %llu\n",
              ours.positions.size(), ours.triangles.size(), (unsigned long long)ours.stats.cellsVisited,
              (unsigned long long)ours.stats.cellsCrossed, (unsigned long long)ours.stats.samplePointEvals,
              (unsigned long long)ours.stats.rootEvals, (unsigned long long)ours.stats.gradientEvals);

  // frep mesh's default: the merged mesh simplified (0.1 voxel, sharp features; single thread).
  // Up to 256^3 only: at ~25 us per input triangle 512^3 takes minutes.
  Mesh simplified;
  if (n <= 256) {
    simplified = ours;
    SimplifyOptions so;
    so.tolerance = 0.1;
    auto t0 = Clock::now();
    const double c0 = cpuSeconds();
    SimplifyStats st = simplifyMesh(simplified, tape, grid, so);
    const double t = seconds(t0), c = cpuSeconds() - c0;
    std::printf("  simplify (tolerance 0.1 voxel): %zu -> %zu triangles in %.2f s (cpu %.2f s, %.1f us per input "
                "triangle), %llu model evaluations, error bound %.3f voxel\n",
                ours.triangles.size(), simplified.triangles.size(), t, c, 1e6 * c / double(ours.triangles.size()),
                (unsigned long long)st.modelEvals, st.errorBound / grid.voxel);
  }

  // Accuracy.
  auto t0 = Clock::now();
  std::vector<Vec3> surf = surfacePoints(tape, grid);
  if (!simplified.triangles.empty()) {
    Soup s = soupOf(simplified);
    simplified = Mesh();
    Stat ms = meshToSurface(tape, s, grid.voxel), sm = surfaceToMesh(surf, s, grid);
    printHausdorff("frepfarm simplified", ms, sm, surf.size());
  }
  {
    Soup s = soupOf(ours);
    std::vector<Vec3>().swap(ours.positions);
    Stat ms = meshToSurface(tape, s, grid.voxel), sm = surfaceToMesh(surf, s, grid);
    printHausdorff("frepfarm meshGrid", ms, sm, surf.size());
  }
  ours = Mesh();
  {
    Soup s = soupOf(vpts, vquads);
    std::vector<openvdb::Vec3s>().swap(vpts);
    std::vector<openvdb::Vec4I>().swap(vquads);
    Stat ms = meshToSurface(tape, s, grid.voxel), sm = surfaceToMesh(surf, s, grid);
    printHausdorff("OpenVDB volumeToMesh", ms, sm, surf.size());
  }
  std::printf("  (accuracy measured in %.1f s)\n", seconds(t0));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes{256, 512};
  bool farm = true;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--quick") sizes = {128};
    else if (a == "--no-farm") farm = false;
    else if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      std::string item;
      while (std::getline(ss, item, ',')) sizes.push_back(std::atoi(item.c_str()));
    } else {
      std::fprintf(stderr, "usage: bench_mesh [--quick] [--sizes 256,512] [--no-farm]\n");
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress visible when redirected
  openvdb::initialize();
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  TapePtr tape = Tape::compile(gyroidModel(), 3);
  double load[3] = {0, 0, 0};
  if (FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = -1;
    std::fclose(f);
  }
  std::printf("bench_mesh: f = min(1 - |x|^2, 0.3 - |sin 8x cos 8y + sin 8y cos 8z + sin 8z cos 8x|) over [%g, %g]^3\n"
              "%d hardware threads, load average %.2f at start; tape %zu instructions\n",
              kLo, kHi, cores, load[0], tape->size());
  for (int n : sizes) runSize(tape, n, cores);

  // libfive's published figure: sphere ∩ gyroid, 10^3 region at 0.025 (400^3 equivalent) in
  // about 3 s after its thread-pool rewrite, i.e. ~21 M voxel-eq/s on a multi-core machine.
  std::printf("\nlibfive (published): ~21 M voxel-eq/s on sphere ∩ gyroid, multi-core; per core "
              "%.1f M/s if 4 cores, %.1f M/s if 8 (its core count is not stated). Measured on this machine\n"
              "against frep mesh by bench/bench_mesh_libfive.py (needs a libfive build; docs/mesh.md).\n",
              21.0 / 4, 21.0 / 8);

  if (farm) {
    char tmpl[] = "/tmp/bench_mesh_XXXXXX";
    if (!::mkdtemp(tmpl)) return 0;
    std::printf("\nfarm master memory (frep mesh, embedded local workers; report's peak_rss_bytes):\n");
    for (int n : sizes) farmRun(n, tmpl);
    std::remove((std::string(tmpl) + "/gyroid.hf").c_str());
    std::remove((std::string(tmpl) + "/out.txt").c_str());
    ::rmdir(tmpl);
  }
  return 0;
}
