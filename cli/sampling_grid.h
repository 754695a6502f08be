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

// Grid over the first `axes` axes of `box` (the others get one point at lo). The voxel is the
// largest extent / cells ratio (extent / (res - 1) for --res); the points are the world lattice
// (integer multiples of the voxel from the world origin, as OpenVDB's index space) that covers
// the box rounded outward to it, so -g N on a cube whose bounds are multiples of the voxel gives
// hfp's N + 1 points and a box off the lattice one point more on the axes it is off.
GridSpec makeGrid(const Box& box, int axes, const Resolution& r);

}  // namespace frep::cli

namespace frep::cli {

// From --res (0 if not given) and -g text ("" if not given); neither: defaultRes.
// field names are used in messages; throws CliError(kExitBadArgs).
Resolution resolutionFrom(int res, const std::string& cellsText, int defaultRes);

}  // namespace frep::cli
