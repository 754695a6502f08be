#include "sampling_grid.h"

#include <algorithm>
#include <cmath>

#include "exit_codes.h"

namespace frep::cli {

namespace {

double voxelOf(const Box& box, int axes, const Resolution& r) {
  double voxel = 0.0;
  for (int a = 0; a < axes; ++a) {
    double extent = box.hi[a] - box.lo[a];
    voxel = std::max(voxel, r.res > 0 ? extent / double(r.res - 1) : extent / double(r.cells[a]));
  }
  return voxel;
}

}  // namespace

GridSpec makeGrid(const Box& box, int axes, const Resolution& r) {
  GridSpec g;
  g.origin = box.lo;
  g.voxel = voxelOf(box, axes, r);
  for (int a = 0; a < 3; ++a) {
    if (a >= axes) { g.dims[a] = 1; continue; }
    // As GridSpec::fromBounds: points stay inside the box; 1e-9 keeps an extent that is a whole
    // number of voxels up to rounding from losing its last point.
    double steps = std::floor((box.hi[a] - box.lo[a]) / g.voxel + 1e-9);
    g.dims[a] = static_cast<int32_t>(steps) + 1;
  }
  return g;
}

GridSpec makeWorldLatticeGrid(const Box& box, const Resolution& r) {
  GridSpec g;
  g.voxel = voxelOf(box, 3, r);
  for (int a = 0; a < 3; ++a) {
    // Integer multiples of the voxel, the box rounded outward to them (1e-9 keeps a bound that
    // is a whole number of voxels up to rounding where it is, so it gains no point).
    const double lo = std::floor(box.lo[a] / g.voxel + 1e-9), hi = std::ceil(box.hi[a] / g.voxel - 1e-9);
    // OpenVDB's coordinates are 32-bit: a box far from the origin at a fine voxel has none.
    if (std::max(std::abs(lo), std::abs(hi)) > double(kMaxLatticeIndex))
      throw badArgs("-b/--bounds: the box reaches " + std::to_string(std::max(std::abs(lo), std::abs(hi)) * g.voxel) +
                    ", more than " + std::to_string(kMaxLatticeIndex) + " voxels of " + std::to_string(g.voxel) +
                    " from the origin (OpenVDB's index range); use a coarser --res/-g or move the model");
    g.origin[a] = lo * g.voxel;
    g.dims[a] = static_cast<int32_t>(hi - lo) + 1;
  }
  return g;
}

Resolution resolutionFrom(int res, const std::string& cellsText, int defaultRes) {
  Resolution r;
  if (!cellsText.empty()) {
    if (res != 0) throw badArgs("--res and -g/--grid: give one of them, not both");
    r.cells = parseCells("-g/--grid", cellsText);
    return r;
  }
  if (res == 0) res = defaultRes;
  if (res < 2 || res > kMaxCells + 1)
    throw badArgs("--res: expected an integer from 2 to " + std::to_string(kMaxCells + 1) + ", got " +
                  std::to_string(res));
  r.res = res;
  return r;
}

}  // namespace frep::cli
