// Sparse sampling of a model on a regular grid: values only in 8^3 leaf blocks near the
// surface, inside/outside tiles elsewhere, found by recursive interval subdivision with tape
// pruning, so the cost follows the surface, not the volume. This is the in-process reference
// that the farm distributes brick by brick.
#pragma once

#include <array>
#include <limits>
#include <cstdint>
#include <functional>
#include <vector>

#include "frep/expressions/tape.h"
#include "frep/interrupt/interrupter.h"

namespace frep {

// Voxel (i, j, k) sits at world point origin + (i, j, k) * voxel; 0 <= i < dims[0], ...
struct GridSpec {
  std::array<double, 3> origin{0, 0, 0};
  double voxel = 1.0;
  std::array<int32_t, 3> dims{0, 0, 0};
  std::array<double, 3> world(int64_t i, int64_t j, int64_t k) const {
    return {origin[0] + double(i) * voxel, origin[1] + double(j) * voxel, origin[2] + double(k) * voxel};
  }
  // The grid that spans [lo, hi] with n voxels along the longest axis (n >= 2), others in step.
  static GridSpec fromBounds(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int n);
};

constexpr int kLeafDim = 8;  // OpenVDB leaf nodes are 8^3
constexpr int kLeafVoxels = kLeafDim * kLeafDim * kLeafDim;

// Index of voxel (x, y, z) inside a leaf, as OpenVDB orders it: x major, z minor.
inline int leafOffset(int x, int y, int z) { return (x << 6) | (y << 3) | z; }

struct LeafBlock {
  // Not zeroed, even as LeafBlock{} or by a vector's resize(): every maker writes all of it
  // (the farm's merge decodes 1 GB of leaves straight into a resized vector; zeroing them first
  // was a third pass over that memory). cleared(): origin 0, every value 0, no voxel active.
  LeafBlock() noexcept {}
  static LeafBlock cleared() {
    LeafBlock l;
    l.origin.fill(0);
    l.values.fill(0.0f);
    l.active.fill(0);
    return l;
  }
  std::array<int32_t, 3> origin;  // multiple of 8 (index space)
  // f at each voxel (F-rep sign: >= 0 inside). Voxels outside the band, or outside the grid,
  // are inactive and hold +band (inside) or -band (outside), in world units: band * voxel.
  std::array<float, kLeafVoxels> values;
  std::array<uint64_t, kLeafVoxels / 64> active;  // bit per voxel, same order as values
  bool isActive(int offset) const { return (active[offset >> 6] >> (offset & 63)) & 1u; }
};

struct Tile {
  std::array<int32_t, 3> origin;  // multiple of 8
  int32_t size;                    // edge length in voxels (power of two >= 8)
  bool inside;                     // the whole cube is inside (f > 0) or outside (f < 0)
};

// The sign rule: inside when f >= 0 (both zeros: a point on the boundary belongs to the closed
// solid, as in the papers) and not NaN. Stored floats keep the class of the double they come
// from (storedValue), so sampled values and direct evaluations classify every point the same way.
inline bool insideValue(double f) { return f >= 0; }
// f as a float of the same class: a negative value too small for a float is stored as the
// negative float nearest 0 (not -0, which would read as inside), a zero of either sign as +0.
inline float storedValue(double f) {
  const float s = static_cast<float>(f);
  if (s != 0.0f) return s;
  return f < 0 ? -std::numeric_limits<float>::denorm_min() : 0.0f;
}

struct SampleOptions {
  // Voxels within this many voxels (Chebyshev) of a possible zero are sampled. 0: only the
  // points of 2^3 blocks whose own box may hold a zero (every other point keeps a certified sign
  // as +-0: what the mesher of extremum models reads).
  int bandVoxels = 3;
  // The smallest block inside a leaf that intervals classify: 2 (2^3 blocks; every evaluated
  // point is near a possible zero) or 4 (4^3: fewer intervals, more points, some far inside a
  // 4^3 box's loose bound). 4 where the band's distance trims the active set afterwards
  // (bandDistance, exactBandDistance: frep sample's distance stores): the chair at 512^3 took
  // 0.77 s against 1.36 s (docs/sample_performance.md, "Sparse sampling against dense evaluation").
  int leafBlock = 2;
  // Extremum searches start cold in every lane, so every value is a function of its point (as
  // PointEvaluator's) whatever the region: the mesher's signs. Default: warm-started lanes.
  bool pointwiseSearches = false;
  // With pointwiseSearches: a model whose result is an extremum node stores values of which
  // only the sign is the cold search's (ExtremumSolver::solveSign): for readers of signs only.
  bool extremumSignsOnly = false;
  // Only the class of each stored value is read (the mesher): a field object that is the
  // tape's result gives its class alone (FieldFunction::signs), not its value. A Minkowski sum
  // of meshes classifies a point outside without its distance to the boundary pieces, which was
  // 28 % of bunny ⊕ tetrahedral tool at 128³ (docs/mesh.md).
  bool fieldSignsOnly = false;
  // Every cube of 8^3 or more is classified over its points and the next point on each high
  // side, so a tile's sign holds on all corners of its cells (what a mesher reading the cells of
  // leaves only needs; a band of 1 or more covers them anyway).
  bool tilesCoverCells = false;
  // Index-space region to sample, [lo, hi) per axis; lo must be a multiple of 8. Default: all.
  std::array<int32_t, 3> regionLo{0, 0, 0};
  std::array<int32_t, 3> regionHi{-1, -1, -1};
  std::vector<double> fixedCoords;  // values of x[3], x[4], ... for models of dimension > 3
  int threads = 0;                  // 0: TBB's default; 1: serial (deterministic either way)
  // Cancel and progress ("sample": work cubes done of total); null: the caller's, if any.
  const Interrupter* interrupt = nullptr;
};

struct SampleStats {
  uint64_t pointEvals = 0;     // model evaluations at grid points
  uint64_t intervalEvals = 0;  // interval evaluations over boxes
  uint64_t denseEvals = 0;     // what a dense evaluation of the region would cost
  uint64_t nanValues = 0;      // samples whose value was NaN (domain errors), stored as outside
  DomainCounts domainErrors;   // evaluations that used a documented domain-error value
  uint64_t tapeInstrs = 0;     // sum of pruned tape lengths used for point batches ...
  uint64_t tapeBatches = 0;    // ... over this many batches (average = tapeInstrs / tapeBatches)
};

struct SampleResult {
  GridSpec grid;
  int bandVoxels = 3;
  std::vector<LeafBlock> leaves;  // sorted by origin (x, then y, then z)
  std::vector<Tile> tiles;        // sorted by origin
  SampleStats stats;
};

SampleResult sample(const TapePtr& tape, const GridSpec& grid, const SampleOptions& options = {});

// Puts leaves and tiles in the canonical order (by origin: x, then y, then z). Leaves are 2 KiB
// each, so they are ordered through an index and moved once.
void sortByOrigin(std::vector<LeafBlock>& leaves, std::vector<Tile>& tiles);

// Volume of the inside of a sampled model as counted on its lattice: the grid points with
// f >= 0 (voxels of inside tiles and leaf values >= 0, within the grid) times the voxel volume.
double insideVolume(const SampleResult& r);

// Which faces of the grid's box the solid reaches: bit 2a for the low face along axis a, bit
// 2a + 1 for the high one, set when a grid point on that face is inside (f >= 0). Found by
// sampling each face's layer of points (band 0: interval-certified tiles, only points near the
// surface evaluated), so a solid well inside the box costs a few interval evaluations.
unsigned facesReached(const TapePtr& tape, const GridSpec& grid, const std::vector<double>& fixedCoords = {},
                      int threads = 0);
// The same count for a shape given by a predicate on world points: the grid points p of g with
// inside(p), times the voxel volume.
double latticeVolume(const GridSpec& g, const std::function<bool(const std::array<double, 3>&)>& inside);

}  // namespace frep
