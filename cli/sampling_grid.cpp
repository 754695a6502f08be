#include "sampling_grid.h"

#include <algorithm>
#include <cmath>

#include "exit_codes.h"

namespace frep::cli {

GridSpec makeGrid(const Box& box, int axes, const Resolution& r) {
  GridSpec g;
  double voxel = 0.0;
  for (int a = 0; a < axes; ++a) {
    double extent = box.hi[a] - box.lo[a];
    voxel = std::max(voxel, r.res > 0 ? extent / double(r.res - 1) : extent / double(r.cells[a]));
  }
  g.voxel = voxel;
  for (int a = 0; a < 3; ++a) {
    if (a >= axes) {
      g.origin[a] = box.lo[a];
      g.dims[a] = 1;
      continue;
    }
    // The world lattice: points at integer multiples of the voxel, the box rounded outward to it
    // (1e-9 keeps a bound that is a whole number of voxels up to rounding where it is).
    const double lo = std::floor(box.lo[a] / voxel + 1e-9), hi = std::ceil(box.hi[a] / voxel - 1e-9);
    g.origin[a] = lo * voxel;
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
