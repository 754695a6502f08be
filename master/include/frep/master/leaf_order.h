// Where the merged leaves go: the master's output is sorted by origin (as sample() sorts it),
// and each brick's payload is decoded straight into its leaves' places (Master::mergeLeaves).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace frep::farm {

// rank[i]: the place of origins[i] among all the origins sorted, ties by i (the leaves of a slab
// of bricks, brick by brick, each in payload order: a worker may repeat an origin). Every origin
// must lie in the box [lo, hi), on the 8-grid from lo (verified leaves of the box's bricks do);
// one outside is std::logic_error. A counting sort over the box's cells of 8^3 when there are
// at most maxCellsPerLeaf of them per origin (the usual slab), else a comparison sort (a sparse
// slab of a large grid); the same ranks either way.
void rankByOrigin(const std::vector<std::array<int32_t, 3>>& origins, const std::array<int32_t, 3>& lo,
                  const std::array<int32_t, 3>& hi, std::vector<size_t>& rank, size_t maxCellsPerLeaf = 8);

}  // namespace frep::farm
