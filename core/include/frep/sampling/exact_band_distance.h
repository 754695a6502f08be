// The narrow band of a sampled region as the exact distance to the samples' piecewise-linear
// zero set, computed from the region's samples and a halo of the band's width around it: what
// `frep sample --store sdf-exact` stores, per brick on the workers, with no global mesh.
//
// Each cell of the lattice (a cube of 8 samples) is split into the 6 tetrahedra of Kuhn's
// triangulation (along its diagonal from the low corner to the high one, the same split in every
// cell, so the pieces of neighbouring cells meet on their shared faces); f is taken linear on
// each tetrahedron, interpolating the samples, and its zero set there is a triangle or a
// quadrilateral (two triangles). A band voxel stores its distance to those triangles, computed
// in double in a fixed order of operations from the voxel's neighbourhood alone, signed by its
// own sample. The halo is sampled exactly as the neighbouring bricks sample it (same blocks,
// same band), so every brick that builds a cell builds the same triangles and the bytes are the
// same for any split into bricks and any number of workers.
#pragma once

#include <string>

#include "frep/sampling/band_distance.h"

namespace frep {

// Replaces the evaluated values of r's leaves (a region sampled by sample(tape, grid, opt) with
// opt.bandVoxels >= 1) by the signed distance to the piecewise-linear zero set of the lattice's
// samples, in world units (F-rep sign: positive inside), active where it is below the band,
// +-band inactive elsewhere. Halo points are evaluated as the sampler evaluates them (opt's
// extremum options; set opt.pointwiseSearches for brick-independent values of extremum models).
void exactBandDistance(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, SampleResult& r,
                       BandDistanceStats* stats = nullptr);

// The stored value's error statement, for a file's metadata and a job's report.
std::string exactBandDistanceBound();

}  // namespace frep
