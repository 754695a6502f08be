#include "frep/io/world_lattice.h"

#include <algorithm>
#include <cmath>

#include "frep/io/error.h"

namespace frep::io {

GridSpec worldLatticeGrid(const std::string& field, const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                          double voxel) {
  GridSpec g;
  g.voxel = voxel;
  for (int a = 0; a < 3; ++a) {
    // The box rounded outward to the lattice (1e-9 keeps a bound that is a whole number of
    // voxels up to rounding where it is, so it gains no point).
    const double l = std::floor(lo[a] / voxel + 1e-9), h = std::ceil(hi[a] / voxel - 1e-9);
    if (std::max(std::abs(l), std::abs(h)) > double(kMaxLatticeIndex))
      throw badArgs(field + ": the box reaches " + std::to_string(std::max(std::abs(l), std::abs(h)) * voxel) +
                    ", more than " + std::to_string(kMaxLatticeIndex) + " voxels of " + std::to_string(voxel) +
                    " from the origin (OpenVDB's index range); use a coarser voxel or move the model");
    g.origin[a] = l * voxel;
    g.dims[a] = static_cast<int32_t>(h - l) + 1;
  }
  return g;
}

GridSpec leafAlignedGrid(const GridSpec& g) {
  GridSpec a = g;
  for (int k = 0; k < 3; ++k) {
    const int64_t index = std::llround(g.origin[k] / g.voxel);
    const int64_t below = index & 7;  // 0..7, also for negative indices (two's complement)
    a.origin[k] = double(index - below) * g.voxel;
    a.dims[k] = g.dims[k] + int32_t(below);
  }
  return a;
}

}  // namespace frep::io
