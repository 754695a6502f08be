// The grid of points on the world lattice (integer multiples of the voxel from the world origin:
// OpenVDB's index space, which writeLevelSet writes) that covers the box lo..hi rounded outward
// to it; grids of other tools with the same voxel then line up. frep sample and the Python
// module's sample() both take their grids from here.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "frep/sampling/sample.h"

namespace frep::io {

constexpr int64_t kMaxLatticeIndex = int64_t(1) << 30;  // OpenVDB's coordinates are 32-bit

// Throws Error(kExitBadArgs) naming `field` when a lattice index would pass kMaxLatticeIndex.
GridSpec worldLatticeGrid(const std::string& field, const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                          double voxel);

}  // namespace frep::io
