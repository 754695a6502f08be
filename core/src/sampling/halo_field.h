// A sampled region's values and a halo of voxels around it on one dense array, the halo
// evaluated exactly where (and as) the sampler evaluates it when it samples the neighbouring
// region: what the per-region distances of `frep sample` read (band_distance.h with a halo of
// one voxel, exact_band_distance.h with one of the band's width), so that a voxel's value is a
// function of its neighbourhood on the lattice alone, the same for any split into regions.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "frep/sampling/band_distance.h"

namespace frep::detail {

class HaloField {
 public:
  // The region of r (opt.regionLo, opt.regionHi clipped to the grid) and `halo` voxels around
  // it (clipped to the grid): r's active values, then the halo's values where the sampler
  // evaluates them; NaN wherever a value was not evaluated (a sign certified without one).
  HaloField(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, const SampleResult& r, int halo,
            BandDistanceStats& stats);
  ~HaloField();  // the thread's array all NaN again
  HaloField(const HaloField&) = delete;
  HaloField& operator=(const HaloField&) = delete;

  // [lo, hi) per axis: the array's box; [coreLo, coreHi): the region's.
  int64_t lo[3], hi[3], n[3], coreLo[3], coreHi[3];
  int64_t s0, s1;  // strides of x and y (z is 1)
  int64_t at(int64_t i, int64_t j, int64_t k) const { return (i - lo[0]) * s0 + (j - lo[1]) * s1 + (k - lo[2]); }
  bool inBox(int64_t i, int64_t j, int64_t k) const {
    return i >= lo[0] && i < hi[0] && j >= lo[1] && j < hi[1] && k >= lo[2] && k < hi[2];
  }
  const float* values() const { return value_->data(); }
  // The array's indices that hold a value (the region's first, then the halo's).
  const std::vector<int64_t>& evaluated() const { return evaluated_; }

 private:
  void clear();
  std::vector<float>* value_;  // the thread's array, kept between calls
  std::vector<int64_t> evaluated_;
};

// Voxel n of a band leaf set to the distance d (>= 0) signed by `inside`: an outside voxel keeps
// its sign (sample.h storedValue: never -0); at or past the band's edge the background, and the
// voxel leaves the band.
inline void storeBandDistance(LeafBlock& l, int64_t n, float d, bool inside, float background) {
  if (d < background) {
    l.values[size_t(n)] = inside ? d : (d > 0 ? -d : -std::numeric_limits<float>::denorm_min());
  } else {
    l.values[size_t(n)] = inside ? background : -background;
    l.active[size_t(n >> 6)] &= ~(uint64_t(1) << (n & 63));
  }
}

}  // namespace frep::detail
