// Signed distance of a sampled region's band from its own samples (see band_distance.h).
#include "frep/sampling/band_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sampling/halo_field.h"
#include "sampling/parallel_chunks.h"

namespace frep {

std::string bandDistanceBound() {
  return "second-order estimate from the sampled lattice: f's Taylor expansion to second order (central "
         "differences) solved for its zero along the gradient; exact where f is linear, and where f is quadratic "
         "along straight gradient lines (a ball's r^2 - |x|^2); not certified elsewhere: near a crease of min/max or "
         "R-function combinations it underestimates, by up to the band's width";
}

void bandDistance(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, SampleResult& r,
                  BandDistanceStats* stats) {
  if (opt.bandVoxels < 1) throw std::invalid_argument("bandDistance: the band must be at least 1 voxel");
  BandDistanceStats local;
  BandDistanceStats& st = stats ? *stats : local;
  if (r.leaves.empty()) return;  // tiles only: every point further than the band from a zero
  // The region and a voxel around it (the stencil's reach), NaN where not evaluated.
  const detail::HaloField f(tape, grid, opt, r, 1, st);
  const int64_t core[2][3] = {{f.coreLo[0], f.coreLo[1], f.coreLo[2]}, {f.coreHi[0], f.coreHi[1], f.coreHi[2]}};

  // Each evaluated voxel of the region: f's gradient g and Hessian H by central differences of
  // its neighbours (one-sided, first order, where one was not evaluated), then the nearest zero
  // of f(v - s n) = f - s |g| + s^2 n.H.n / 2 along the unit gradient n (a ball's r^2 - |x|^2:
  // exactly its distance), in the stable form 2 f / (|g| + sqrt(|g|^2 - 2 f n.H.n)).
  const float background = float(opt.bandVoxels * grid.voxel);
  const double h = grid.voxel;
  const float* value = f.values();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto estimateLeaf = [&](LeafBlock& l) {
    for (int n = 0; n < kLeafVoxels; ++n) {
      if (!l.isActive(n)) continue;
      const int64_t c[3] = {l.origin[0] + (n >> 6), l.origin[1] + ((n >> 3) & 7), l.origin[2] + (n & 7)};
      if (c[0] >= core[1][0] || c[1] >= core[1][1] || c[2] >= core[1][2]) continue;
      // The 3^3 neighbourhood, NaN where not evaluated or past the grid.
      const int64_t at = f.at(c[0], c[1], c[2]);
      const double f0 = l.values[size_t(n)];
      float q[3][3][3];
      const bool interior = c[0] > f.lo[0] && c[0] + 1 < f.hi[0] && c[1] > f.lo[1] && c[1] + 1 < f.hi[1] &&
                            c[2] > f.lo[2] && c[2] + 1 < f.hi[2];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const float* row = value + at + (i - 1) * f.s0 + (j - 1) * f.s1;
          for (int k = 0; k < 3; ++k)
            q[i][j][k] = interior || (c[0] + i - 1 >= f.lo[0] && c[0] + i - 1 < f.hi[0] && c[1] + j - 1 >= f.lo[1] &&
                                      c[1] + j - 1 < f.hi[1] && c[2] + k - 1 >= f.lo[2] && c[2] + k - 1 < f.hi[2])
                             ? row[k - 1]
                             : nan;
        }
      // Along axis a, the neighbour at offset d (-1 or 1); across axes a < b, offsets da, db.
      auto along = [&](int a, int d) -> double {
        return q[a == 0 ? 1 + d : 1][a == 1 ? 1 + d : 1][a == 2 ? 1 + d : 1];
      };
      auto across = [&](int a, int da, int b, int db) -> double {
        int o[3] = {1, 1, 1};
        o[a] += da, o[b] += db;
        return q[o[0]][o[1]][o[2]];
      };
      double g[3], H[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
      for (int a = 0; a < 3; ++a) {
        const double lo = along(a, -1), hi = along(a, 1);
        if (!std::isnan(lo) && !std::isnan(hi)) {
          g[a] = (hi - lo) / (2 * h);
          H[a][a] = (hi - 2 * f0 + lo) / (h * h);
        } else if (!std::isnan(hi)) {
          g[a] = (hi - f0) / h;
        } else if (!std::isnan(lo)) {
          g[a] = (f0 - lo) / h;
        } else {
          g[a] = 0;
        }
      }
      for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
          const double pp = across(a, 1, b, 1), pm = across(a, 1, b, -1), mp = across(a, -1, b, 1),
                       mm = across(a, -1, b, -1);
          if (!std::isnan(pp + pm + mp + mm)) H[a][b] = H[b][a] = (pp - pm - mp + mm) / (4 * h * h);
        }
      const double gn = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      double s;
      if (!(gn > 0)) {
        s = f0 == 0 ? 0.0 : std::copysign(double(background), f0);  // flat: no estimate
      } else {
        double nHn = 0;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) nHn += g[a] * H[a][b] * g[b];
        nHn /= gn * gn;
        const double disc = gn * gn - 2 * f0 * nHn;
        s = disc > 0 ? 2 * f0 / (gn + std::sqrt(disc)) : f0 / gn;  // no real root: first order
      }
      const float d = float(std::fabs(s));
      const bool inside = f0 >= 0;
      detail::storeBandDistance(l, n, d, inside, background);
    }
  };
  // Leaves in parallel (in-process runs sample a brick on every core): each writes only its own
  // values and reads the array, so the result does not depend on the threads.
  parallelChunks(r.leaves.size(), 16, opt.threads, [&](size_t first, size_t last) {
    for (size_t li = first; li != last; ++li) estimateLeaf(r.leaves[li]);
  });
}

}  // namespace frep
