// Signed distance of a sampled region's band from its own samples (see band_distance.h).
#include "frep/sampling/band_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "frep/evaluators/eval.h"
#include "sampling/parallel_chunks.h"

namespace frep {
namespace {

// The region and a voxel around it on a dense array: the sampled values, NaN where the sampler
// decided the sign without evaluating. Kept between calls on a thread and all NaN between them,
// so a call cleans only what it set.
struct Scratch {
  std::vector<float> value;
};

struct Field {
  int64_t lo[3], hi[3], n[3], s0, s1;
  Scratch& s;
  explicit Field(Scratch& scratch) : s(scratch) {}
  void reserve() {
    if (s.value.size() >= size()) return;
    s.value.resize(size(), std::numeric_limits<float>::quiet_NaN());
  }
  size_t size() const { return size_t(n[0] * n[1] * n[2]); }
  int64_t at(int64_t i, int64_t j, int64_t k) const { return (i - lo[0]) * s0 + (j - lo[1]) * s1 + (k - lo[2]); }
};

// Evaluates the points of a box of the halo that the sampler evaluates when it samples the
// brick they belong to: a point's value is computed when the interval of f over its 2^3 block
// (on the lattice's 2-grid, clipped to the grid) and the band around it may hold a zero. Blocks
// of 8^3 around them, and the box, are classified first (a larger box's interval holds the
// smaller's: interval arithmetic is inclusion-monotone), so the same points are evaluated.
class HaloSampler {
 public:
  HaloSampler(const GridSpec& g, const SampleOptions& opt, uint32_t nvars, BandDistanceStats& st)
      : g_(g), opt_(opt), nvars_(nvars), st_(st) {
    interval_.setExtremumBudgetOnly(opt.pointwiseSearches && opt.extremumSignsOnly);
  }

  // [lo, hi) per axis, inside the field's box.
  void box(const TapePtr& tape, const int64_t* lo, const int64_t* hi, Field& f, std::vector<int64_t>& evaluated) {
    for (int a = 0; a < 3; ++a)
      if (lo[a] >= hi[a]) return;
    auto down = [](int64_t v, int64_t m) { return v - ((v % m) + m) % m; };
    auto up = [&](int64_t v, int64_t m, int a) { return std::min<int64_t>(down(v + m - 1, m), g_.dims[a]) - 1; };
    if (decided(*tape, {down(lo[0], 8), down(lo[1], 8), down(lo[2], 8)},
                {up(hi[0], 8, 0), up(hi[1], 8, 1), up(hi[2], 8, 2)}))
      return;
    const TapePtr boxTape = interval_.pruned(tape);
    for (int64_t bx = down(lo[0], 8); bx < hi[0]; bx += 8)
      for (int64_t by = down(lo[1], 8); by < hi[1]; by += 8)
        for (int64_t bz = down(lo[2], 8); bz < hi[2]; bz += 8) {
          if (decided(*boxTape, {bx, by, bz}, {up(bx + 8, 8, 0), up(by + 8, 8, 1), up(bz + 8, 8, 2)})) continue;
          const TapePtr blockTape = interval_.pruned(boxTape);
          todo_.clear();
          for (int64_t ex = std::max(bx, down(lo[0], 2)); ex < std::min(bx + 8, hi[0]); ex += 2)
            for (int64_t ey = std::max(by, down(lo[1], 2)); ey < std::min(by + 8, hi[1]); ey += 2)
              for (int64_t ez = std::max(bz, down(lo[2], 2)); ez < std::min(bz + 8, hi[2]); ez += 2) {
                if (decided(*blockTape, {ex, ey, ez}, {up(ex + 2, 2, 0), up(ey + 2, 2, 1), up(ez + 2, 2, 2)})) continue;
                for (int64_t x = std::max(ex, lo[0]); x < std::min(ex + 2, hi[0]); ++x)
                  for (int64_t y = std::max(ey, lo[1]); y < std::min(ey + 2, hi[1]); ++y)
                    for (int64_t z = std::max(ez, lo[2]); z < std::min(ez + 2, hi[2]); ++z) todo_.push_back({x, y, z});
              }
          evaluate(*blockTape, f, evaluated);
        }
  }

 private:
  // True when f has one sign over the box's points [lo, hi] and the band around them.
  bool decided(const Tape& tape, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
    const int64_t d = opt_.bandVoxels;
    box_.resize(std::max<size_t>(nvars_, 1));
    for (uint32_t v = 0; v < nvars_; ++v)
      box_[v] = v < 3
                    ? Interval(g_.origin[v] + double(lo[v] - d) * g_.voxel, g_.origin[v] + double(hi[v] + d) * g_.voxel)
                    : Interval(opt_.fixedCoords[v - 3]);
    ++st_.haloIntervalEvals;
    const Interval iv = interval_.eval(tape, box_.data());
    return iv.lo > 0 || iv.hi < 0;
  }

  void evaluate(const Tape& tape, Field& f, std::vector<int64_t>& evaluated) {
    constexpr size_t B = BatchEvaluator<double>::kBatch;
    batch_.reserve(tape);
    batch_.setExtremumWarmStarts(!opt_.pointwiseSearches);
    batch_.setExtremumSignsOnly(opt_.pointwiseSearches && opt_.extremumSignsOnly);
    for (size_t start = 0; start < todo_.size(); start += B) {
      const size_t count = std::min(B, todo_.size() - start);
      for (size_t k = 0; k < count; ++k)
        for (uint32_t v = 0; v < nvars_; ++v)
          batch_.in(v)[k] = v < 3 ? g_.origin[v] + double(todo_[start + k][v]) * g_.voxel : opt_.fixedCoords[v - 3];
      const double* out = batch_.eval(tape, count);
      for (size_t k = 0; k < count; ++k) {
        if (std::isnan(out[k])) continue;  // not evaluated, as the sampler stores it
        const auto& p = todo_[start + k];
        const int64_t l = f.at(p[0], p[1], p[2]);
        f.s.value[size_t(l)] = storedValue(out[k]);
        evaluated.push_back(l);
      }
      st_.haloPointEvals += count;
    }
  }

  const GridSpec& g_;
  const SampleOptions& opt_;
  uint32_t nvars_;
  BandDistanceStats& st_;
  IntervalEvaluator interval_;
  BatchEvaluator<double> batch_;
  std::vector<Interval> box_;
  std::vector<std::array<int64_t, 3>> todo_;
};

}  // namespace

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
  int64_t core[2][3];
  thread_local Scratch scratch;
  Field f(scratch);
  for (int a = 0; a < 3; ++a) {
    core[0][a] = opt.regionLo[a];
    core[1][a] = opt.regionHi[a] < 0 ? grid.dims[a] : std::min(opt.regionHi[a], grid.dims[a]);
    f.lo[a] = std::max<int64_t>(0, core[0][a] - 1);  // a voxel of halo: the stencil's reach
    f.hi[a] = std::min<int64_t>(grid.dims[a], core[1][a] + 1);
    f.n[a] = f.hi[a] - f.lo[a];
  }
  f.s1 = f.n[2];
  f.s0 = f.n[1] * f.n[2];
  f.reserve();

  // The region's evaluated points, then the halo's six faces (the x faces take the edges).
  std::vector<int64_t> evaluated;
  struct Clean {  // the thread's array clean again, also when a halo evaluation throws
    Field& f;
    const std::vector<int64_t>& evaluated;
    ~Clean() {
      for (int64_t l : evaluated) f.s.value[size_t(l)] = std::numeric_limits<float>::quiet_NaN();
    }
  } clean{f, evaluated};
  for (const LeafBlock& l : r.leaves)
    for (int n = 0; n < kLeafVoxels; ++n) {
      if (!l.isActive(n)) continue;
      const int64_t i = l.origin[0] + (n >> 6), j = l.origin[1] + ((n >> 3) & 7), k = l.origin[2] + (n & 7);
      if (i >= core[1][0] || j >= core[1][1] || k >= core[1][2]) continue;
      const int64_t at = f.at(i, j, k);
      f.s.value[size_t(at)] = l.values[size_t(n)];
      evaluated.push_back(at);
    }
  HaloSampler halos(grid, opt, tape->numVars(), st);
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      int64_t lo[3], hi[3];
      for (int b = 0; b < 3; ++b) {
        lo[b] = b < a ? core[0][b] : f.lo[b];  // earlier axes' faces hold those edges already
        hi[b] = b < a ? core[1][b] : f.hi[b];
      }
      if (side == 0) hi[a] = core[0][a];
      else lo[a] = core[1][a];
      halos.box(tape, lo, hi, f, evaluated);
    }

  // Each evaluated voxel of the region: f's gradient g and Hessian H by central differences of
  // its neighbours (one-sided, first order, where one was not evaluated), then the nearest zero
  // of f(v - s n) = f - s |g| + s^2 n.H.n / 2 along the unit gradient n (a ball's r^2 - |x|^2:
  // exactly its distance), in the stable form 2 f / (|g| + sqrt(|g|^2 - 2 f n.H.n)).
  const float background = float(opt.bandVoxels * grid.voxel);
  const double h = grid.voxel;
  const std::vector<float>& value = f.s.value;
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
          const float* row = value.data() + at + (i - 1) * f.s0 + (j - 1) * f.s1;
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
      const uint64_t bit = uint64_t(1) << (n & 63);
      const float d = float(std::fabs(s));
      const bool inside = f0 >= 0;
      if (d < background) {
        // An outside voxel keeps its sign (sample.h storedValue): never -0.
        l.values[size_t(n)] = inside ? d : (d > 0 ? -d : -std::numeric_limits<float>::denorm_min());
      } else {
        l.values[size_t(n)] = inside ? background : -background;
        l.active[size_t(n >> 6)] &= ~bit;
      }
    }
  };
  // Leaves in parallel (in-process runs sample a brick on every core): each writes only its own
  // values and reads the array, so the result does not depend on the threads.
  parallelChunks(r.leaves.size(), 16, opt.threads, [&](size_t first, size_t last) {
    for (size_t li = first; li != last; ++li) estimateLeaf(r.leaves[li]);
  });
}

}  // namespace frep
