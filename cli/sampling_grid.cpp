#include "sampling_grid.h"

#include "frep/io/world_lattice.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "exit_codes.h"

namespace frep::cli {

namespace {

double voxelOf(const Box& box, int axes, const Resolution& r) {
  double voxel = 0.0;
  for (int a = 0; a < axes; ++a) {
    double extent = box.hi[a] - box.lo[a];
    voxel = std::max(voxel, r.res > 0 ? extent / double(r.res - 1) : extent / double(r.cells[a]));
  }
  // A derived size must be a positive, finite, normal number (parseBounds keeps the widths
  // finite; a box of 1e-310 divided into voxels underflows).
  if (!(std::isfinite(voxel) && voxel >= std::numeric_limits<double>::min()))
    throw badArgs("-b/--bounds: the box and the resolution give a voxel size of " + std::to_string(voxel) +
                  ", not a positive finite number; choose a larger box or fewer points");
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
  return io::worldLatticeGrid("-b/--bounds", box.lo, box.hi, voxelOf(box, 3, r));
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
