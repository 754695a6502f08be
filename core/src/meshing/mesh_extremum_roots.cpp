// Vertices of models with extremum nodes (mesh_extremum_roots.h).
//
// Every evaluation of such a model runs a branch-and-bound search (about 5 us cold, 2 us when
// warm-started from a nearby arg-extremum), so the generic root finder's 7 evaluations per edge
// plus a Danskin gradient (a search and ~300 body evaluations of polishing, and wrong at the
// kinks where Minkowski bodies reach their maximum) dominated meshing. Here (every sign of the
// cells comes from a cold search or an interval widened by the tolerance, see mesh.cpp):
//   1. values at grid points: every end point of a sign-changing edge and every corner of the
//      Kuhn tetrahedra around one, each a cold search (a function of the point), done once per
//      point and shared by the edges (about half a search per edge);
//   2. root finding along the edge from the two end values: regula falsi first, then the secant
//      through the two latest points on one side of the root (exact where f is linear on that
//      side: Minkowski fields are often kinked at the surface itself, where the search box
//      clamps the arg-extremum), each search warm-started from the arg-extremum of the nearer
//      bracket end; it stops once |f| <= max(rootStopValue, (f(in) - f(out)) / 1024), i.e.
//      within ~1/1024 of the edge where f is linear along it, or after kExtremumRootEvals;
//   3. normal: -(sum of the gradients of the linear interpolants on the tetrahedra around the
//      edge), from the values of step 1: no further search.
#include "meshing/mesh_extremum_roots.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>

#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "sampling/parallel_chunks.h"

namespace frep {

namespace {

constexpr int kExtremumRootEvals = 8;    // searches per edge after its end values
constexpr double kStopFraction = 1.0 / 1024;

using Params = std::vector<std::vector<double>>;  // arg-extremum per extremum entry of the tape

// The Kuhn tetrahedra around grid edge (p, p + d) whose cells lie inside the grid, each as its
// four corners (c, c + e_a, c + e_a + e_b, c + 111) given by the cell corner c and the axis order.
template <typename Fn>
void tetrahedraAround(const std::array<int64_t, 4>& e, const GridSpec& grid, Fn&& fn) {
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const int d = int(e[3]);
  for (int s = 0; s < 8; ++s) {
    // Cell c = p - s (s in {0,1}^3): p and p + d are corners, i.e. s and s + d in {0,1}^3.
    std::array<int64_t, 3> c;
    bool ok = true;
    for (int a = 0; a < 3; ++a) {
      const int sa = (s >> a) & 1, da = (d >> a) & 1;
      c[a] = e[a] - sa;
      ok = ok && sa + da <= 1 && c[a] >= 0 && c[a] + 1 < grid.dims[a];
    }
    if (!ok) continue;
    for (const auto& pm : perms) {
      // Corner masks of the tetrahedron: 0, e_pm0, e_pm0 + e_pm1, 7.
      const int m1 = 1 << pm[0], m2 = m1 | (1 << pm[1]);
      const int corners[4] = {0, m1, m2, 7};
      bool hasP = false, hasQ = false;
      for (int v : corners) {
        hasP = hasP || v == s;
        hasQ = hasQ || v == (s | d);
      }
      if (hasP && hasQ) fn(c, pm);
    }
  }
}

std::array<int64_t, 3> cornerOf(const std::array<int64_t, 3>& c, int mask) {
  return {c[0] + (mask & 1), c[1] + ((mask >> 1) & 1), c[2] + ((mask >> 2) & 1)};
}

uint64_t pointKey(const std::array<int64_t, 3>& p) { return edgeKey(p[0], p[1], p[2], 0); }

struct Worker {
  PointEvaluator point;
  std::vector<double> x;
  Params warm;
  uint64_t evals = 0, fallbacks = 0;

  double eval(const TapePtr& tape, const MeshOptions& opt, const double* p, const Params* from) {
    const uint32_t nv = tape->numVars();
    x.resize(std::max<uint32_t>(nv, 3));
    for (uint32_t v = 0; v < nv; ++v) x[v] = v < 3 ? p[v] : opt.fixedCoords[v - 3];
    point.setWarmStarts(from);
    ++evals;
    return point.eval(*tape, x.data());
  }
};

}  // namespace

void extremumEdgeVertices(const TapePtr& tape, const GridSpec& grid, const MeshOptions& opt,
                          const std::vector<ExtremumEdge>& edges, std::vector<MeshVertex>& vertices, MeshStats& stats) {
  // 1. The grid points whose values the edges need, sorted and unique (each chunk of edges
  // drops its own repeats in parallel first: neighbouring edges share most corners).
  tbb::enumerable_thread_specific<std::vector<uint64_t>> chunkKeys;
  parallelChunks(edges.size(), 256, opt.threads, [&](size_t b, size_t e) {
    std::vector<uint64_t>& out = chunkKeys.local();
    const size_t first = out.size();
    for (size_t i = b; i < e; ++i) {
      tetrahedraAround(edgeKeyParts(edges[i].key), grid, [&](const std::array<int64_t, 3>& c, const int* pm) {
        const int m1 = 1 << pm[0], m2 = m1 | (1 << pm[1]);
        for (int m : {0, m1, m2, 7}) out.push_back(pointKey(cornerOf(c, m)));
      });
    }
    std::sort(out.begin() + long(first), out.end());
    out.erase(std::unique(out.begin() + long(first), out.end()), out.end());
  });
  std::vector<uint64_t> keys;
  for (const std::vector<uint64_t>& k : chunkKeys) keys.insert(keys.end(), k.begin(), k.end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<double> values(keys.size());
  std::vector<Params> params(keys.size());
  tbb::enumerable_thread_specific<Worker> workers;
  parallelChunks(keys.size(), 16, opt.threads, [&](size_t b, size_t e) {
    Worker& w = workers.local();
    for (size_t i = b; i < e; ++i) {
      const auto k = edgeKeyParts(keys[i]);
      const auto p = grid.world(k[0], k[1], k[2]);
      values[i] = w.eval(tape, opt, p.data(), nullptr);
      params[i] = w.point.searchParams();
    }
  });
  auto indexOf = [&](const std::array<int64_t, 3>& p) {
    return size_t(std::lower_bound(keys.begin(), keys.end(), pointKey(p)) - keys.begin());
  };

  // The stop value of step 2 besides the edge's own: as the generic root finder's.
  double noise = opt.rootStopValue;
  if (noise < 0) {
    noise = INFINITY;
    for (const ExtremumEntry& e : tape->extrema())
      noise = std::min(noise, e.spec->method == ExtremumMethod::BranchAndBound ? 0.01 * e.spec->tolerance : 0.0);
  }

  vertices.resize(edges.size());
  parallelChunks(edges.size(), 16, opt.threads, [&](size_t b, size_t e) {
    Worker& w = workers.local();
    for (size_t i = b; i < e; ++i) {
      const ExtremumEdge& edge = edges[i];
      const auto parts = edgeKeyParts(edge.key);
      const int d = int(parts[3]);
      const std::array<int64_t, 3> p0{parts[0], parts[1], parts[2]};
      const std::array<int64_t, 3> p1{parts[0] + (d & 1), parts[1] + ((d >> 1) & 1), parts[2] + ((d >> 2) & 1)};
      const auto& gin = edge.inAtBase ? p0 : p1;
      const auto& gout = edge.inAtBase ? p1 : p0;
      const size_t iin = indexOf(gin), iout = indexOf(gout);
      const auto win = grid.world(gin[0], gin[1], gin[2]), wout = grid.world(gout[0], gout[1], gout[2]);
      double dp[3];
      for (int c = 0; c < 3; ++c) dp[c] = wout[c] - win[c];
      auto at = [&](double t, double* x) {
        for (int c = 0; c < 3; ++c) x[c] = win[c] + t * dp[c];
      };

      // 2. Root finding on t in [0, 1], from the inside end (t = 0) to the outside end.
      double a = 0, b = 1, fa = values[iin], fb = values[iout];
      const Params* pa = &params[iin];
      const Params* pb = &params[iout];
      Params pmid[2];  // arg-extrema of the evaluated points that are bracket ends now
      double t;
      const bool finite = std::isfinite(fa) && std::isfinite(fb);
      const bool inOk = insideValue(fa), outOk = !insideValue(fb);
      if (finite && inOk != outOk) {
        // One end value's sign contradicts the end's sign in the cells (a search or a tile
        // within the tolerance of 0 there): the surface passes that end, the vertex goes there.
        t = inOk ? 1.0 : 0.0;
      } else if (!finite || !inOk) {
        // NaN at an end: bisection, as the generic root finder.
        ++w.fallbacks;
        for (int it = 0; it < opt.rootIterations; ++it) {
          t = 0.5 * (a + b);
          double x[3];
          at(t, x);
          const double f = w.eval(tape, opt, x, t - a <= b - t ? pa : pb);
          if (insideValue(f)) a = t;
          else b = t;
        }
        t = 0.5 * (a + b);
      } else {
        const double stop = std::max(noise, kStopFraction * (fa - fb));
        // The two latest points on each side: [0] the older, [1] the newer.
        double inT[2] = {NAN, 0.0}, inF[2] = {NAN, fa}, outT[2] = {NAN, 1.0}, outF[2] = {NAN, fb};
        auto secant = [](const double* ts, const double* fs) {
          return ts[1] - fs[1] * (ts[1] - ts[0]) / (fs[1] - fs[0]);
        };
        t = fa / (fa - fb);
        for (int k = 0; k < kExtremumRootEvals; ++k) {
          double x[3];
          at(t, x);
          const bool nearA = t - a <= b - t;
          const double f = w.eval(tape, opt, x, nearA ? pa : pb);
          const bool in = insideValue(f);
          // Keep the point's arg-extrema in a slot the other bracket end does not use.
          const Params* replaced = in ? pa : pb;
          const Params* other = in ? pb : pa;
          Params& slot = replaced == &pmid[0] ? pmid[0] : replaced == &pmid[1] ? pmid[1] : other == &pmid[0] ? pmid[1] : pmid[0];
          slot = w.point.searchParams();
          if (in) {
            a = t, fa = f, pa = &slot;
            inT[0] = inT[1], inF[0] = inF[1], inT[1] = t, inF[1] = f;
          } else {
            b = t, fb = f, pb = &slot;
            outT[0] = outT[1], outF[0] = outF[1], outT[1] = t, outF[1] = f;
          }
          if (std::fabs(f) <= stop || !(b - a > 1e-10)) break;
          auto inside = [&](double s) { return s > a && s < b; };
          const double sIn = secant(inT, inF), sOut = secant(outT, outF);
          double next;
          if (in && inside(sIn)) next = sIn;
          else if (!in && inside(sOut)) next = sOut;
          else if (inside(sIn)) next = sIn;
          else if (inside(sOut)) next = sOut;
          else next = a + (b - a) * fa / (fa - fb);
          if (!inside(next)) next = 0.5 * (a + b);  // NaN values on the way
          t = next;
        }
      }
      t = std::min(std::max(t, opt.endGuard), 1.0 - opt.endGuard);
      MeshVertex& v = vertices[i];
      v.key = edge.key;
      for (int c = 0; c < 3; ++c) v.position[c] = win[c] + t * dp[c];

      // 3. Normal: the tetrahedra's gradients in index units (axis pm[j] gets the difference
      // between consecutive corners), summed.
      double g[3] = {0, 0, 0};
      tetrahedraAround(parts, grid, [&](const std::array<int64_t, 3>& c, const int* pm) {
        const int m1 = 1 << pm[0], m2 = m1 | (1 << pm[1]);
        const double f0 = values[indexOf(cornerOf(c, 0))], f1 = values[indexOf(cornerOf(c, m1))];
        const double f2 = values[indexOf(cornerOf(c, m2))], f3 = values[indexOf(cornerOf(c, 7))];
        if (!(std::isfinite(f0) && std::isfinite(f1) && std::isfinite(f2) && std::isfinite(f3))) return;
        g[pm[0]] += f1 - f0;
        g[pm[1]] += f2 - f1;
        g[pm[2]] += f3 - f2;
      });
      double n[3] = {-g[0], -g[1], -g[2]};
      double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(len > 0) || !std::isfinite(len)) {
        for (int c = 0; c < 3; ++c) n[c] = dp[c];
        len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      }
      for (int c = 0; c < 3; ++c) v.normal[c] = n[c] / len;
    }
  });
  for (Worker& w : workers) {
    stats.rootEvals += w.evals;
    stats.fallbackEdges += w.fallbacks;
  }
}

}  // namespace frep
