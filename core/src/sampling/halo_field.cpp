// A region's samples and a halo around them on a dense array (see halo_field.h).
#include "sampling/halo_field.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "frep/evaluators/eval.h"

namespace frep::detail {
namespace {

// Evaluates the points of a box of the halo that the sampler evaluates when it samples the
// brick they belong to: a point's value is computed when the interval of f over its block of
// SampleOptions::leafBlock^3 (on the lattice's grid of that step, clipped to the grid) and the
// band around it may hold a zero. Blocks of 8^3 around them, and the box, are classified first
// (a larger box's interval holds the smaller's: interval arithmetic is inclusion-monotone), so
// the same points are evaluated.
class HaloSampler {
 public:
  HaloSampler(const GridSpec& g, const SampleOptions& opt, uint32_t nvars, BandDistanceStats& st)
      : g_(g), opt_(opt), nvars_(nvars), st_(st) {
    interval_.setExtremumBudgetOnly(opt.pointwiseSearches && opt.extremumSignsOnly);
  }

  // [lo, hi) per axis, inside the field's box.
  void box(const TapePtr& tape, const int64_t* lo, const int64_t* hi, const HaloField& f, float* value,
           std::vector<int64_t>& evaluated) {
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
          const int64_t e = opt_.leafBlock;  // the sampler's smallest block
          for (int64_t ex = std::max(bx, down(lo[0], e)); ex < std::min(bx + 8, hi[0]); ex += e)
            for (int64_t ey = std::max(by, down(lo[1], e)); ey < std::min(by + 8, hi[1]); ey += e)
              for (int64_t ez = std::max(bz, down(lo[2], e)); ez < std::min(bz + 8, hi[2]); ez += e) {
                if (decided(*blockTape, {ex, ey, ez}, {up(ex + e, e, 0), up(ey + e, e, 1), up(ez + e, e, 2)})) continue;
                for (int64_t x = std::max(ex, lo[0]); x < std::min(ex + e, hi[0]); ++x)
                  for (int64_t y = std::max(ey, lo[1]); y < std::min(ey + e, hi[1]); ++y)
                    for (int64_t z = std::max(ez, lo[2]); z < std::min(ez + e, hi[2]); ++z) todo_.push_back({x, y, z});
              }
          evaluate(*blockTape, f, value, evaluated);
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

  void evaluate(const Tape& tape, const HaloField& f, float* value, std::vector<int64_t>& evaluated) {
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
        value[size_t(l)] = storedValue(out[k]);
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

HaloField::HaloField(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, const SampleResult& r,
                     int halo, BandDistanceStats& stats) {
  // Kept between calls on a thread and all NaN between them, so a call cleans only what it set.
  thread_local std::vector<float> scratch;
  value_ = &scratch;
  for (int a = 0; a < 3; ++a) {
    coreLo[a] = opt.regionLo[a];
    coreHi[a] = opt.regionHi[a] < 0 ? grid.dims[a] : std::min<int64_t>(opt.regionHi[a], grid.dims[a]);
    lo[a] = std::max<int64_t>(0, coreLo[a] - halo);
    hi[a] = std::min<int64_t>(grid.dims[a], coreHi[a] + halo);
    n[a] = hi[a] - lo[a];
  }
  s1 = n[2];
  s0 = n[1] * n[2];
  const size_t size = size_t(n[0] * n[1] * n[2]);
  if (scratch.size() < size) scratch.resize(size, std::numeric_limits<float>::quiet_NaN());
  float* value = scratch.data();
  struct Clean {  // the array clean again if a halo evaluation throws
    HaloField* f;
    ~Clean() {
      if (f) f->clear();
    }
  } clean{this};

  // The region's evaluated points, then the halo's six faces (the x faces take the edges).
  for (const LeafBlock& l : r.leaves)
    for (int v = 0; v < kLeafVoxels; ++v) {
      if (!l.isActive(v)) continue;
      const int64_t i = l.origin[0] + (v >> 6), j = l.origin[1] + ((v >> 3) & 7), k = l.origin[2] + (v & 7);
      if (i >= coreHi[0] || j >= coreHi[1] || k >= coreHi[2]) continue;
      const int64_t p = at(i, j, k);
      value[size_t(p)] = l.values[size_t(v)];
      evaluated_.push_back(p);
    }
  HaloSampler halos(grid, opt, tape->numVars(), stats);
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      int64_t blo[3], bhi[3];
      for (int b = 0; b < 3; ++b) {
        blo[b] = b < a ? coreLo[b] : lo[b];  // earlier axes' faces hold those edges already
        bhi[b] = b < a ? coreHi[b] : hi[b];
      }
      if (side == 0) bhi[a] = coreLo[a];
      else blo[a] = coreHi[a];
      halos.box(tape, blo, bhi, *this, value, evaluated_);
    }
  clean.f = nullptr;
}

HaloField::~HaloField() { clear(); }

void HaloField::clear() {
  for (int64_t p : evaluated_) (*value_)[size_t(p)] = std::numeric_limits<float>::quiet_NaN();
  evaluated_.clear();
}

}  // namespace frep::detail
