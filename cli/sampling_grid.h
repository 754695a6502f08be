// The regular grid a command samples: from a box and either --res (points along the longest
// axis) or hfp's -g (cells per axis). Voxels are cubes, as OpenVDB and the sampler need.
#pragma once

#include <array>
#include <string>

#include "arg_parse.h"
#include "frep/sampling/sample.h"

namespace frep::cli {

struct Resolution {
  int res = 0;                     // > 0: this many points along the longest axis
  std::array<int, 3> cells{0, 0, 0};  // else: cells per axis (hfp's -g)
};

// Grid over the first `axes` axes of `box` (the others get one point at lo). The grid starts at
// box.lo; the voxel is the largest extent / cells ratio (extent / (res - 1) for --res), and each
// axis gets the points that fit in the box, so -g N on a cube gives hfp's N + 1 points and
// --res in 3D gives exactly GridSpec::fromBounds. (frep mesh and frep slice.)
GridSpec makeGrid(const Box& box, int axes, const Resolution& r);

// frep sample's grid: the voxel of makeGrid(box, 3, r), the points on the world lattice
// (integer multiples of the voxel from the world origin, OpenVDB's index space, so that grids
// of other tools with the same voxel line up) that covers the box rounded outward to it. A box
// whose bounds are multiples of the voxel gives makeGrid's points; one off the lattice gets a
// point more on each axis it is off.
// (frep/io/world_lattice.h.) Throws CliError(kExitBadArgs) naming -b/--bounds when a lattice
// index passes OpenVDB's range.
GridSpec makeWorldLatticeGrid(const Box& box, const Resolution& r);

}  // namespace frep::cli

namespace frep::cli {

// From --res (0 if not given) and -g text ("" if not given); neither: defaultRes.
// field names are used in messages; throws CliError(kExitBadArgs).
Resolution resolutionFrom(int res, const std::string& cellsText, int defaultRes);

}  // namespace frep::cli
