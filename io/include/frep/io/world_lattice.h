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

// g with its origin moved down to OpenVDB's leaf lattice (a multiple of 8 voxels from the world
// origin; at most 7 more points on each axis, at the same places): the sampler's 8^3 leaves and
// tiles then are OpenVDB's, so the master copies leaves and sets tiles where a misaligned
// lattice filled and pruned partial leaves (docs/sample_performance.md, "Leaf alignment").
GridSpec leafAlignedGrid(const GridSpec& g);

}  // namespace frep::io
