// The narrow band of a sampled region as a signed distance, computed from the region's own
// samples and a one-voxel halo around it: what `frep sample` stores (a distance that OpenVDB's
// tools combine correctly) without a global mesh.
//
// At each evaluated voxel, f's gradient g and Hessian H come from central differences of the
// lattice's values, and the value stored is the nearest zero of f's second-order expansion
// along the gradient direction n: s with f - s|g| + s^2 n.H.n / 2 = 0. That is the distance
// where f is linear, and where f is quadratic along straight gradient lines (a ball's
// r^2 - |x|^2, an exact distance); elsewhere an estimate of second order in the voxel, not a
// certified bound. The halo's values are evaluated exactly where the sampler evaluates them in
// the neighbouring brick (same blocks, SampleOptions::leafBlock, same band), so the result is the
// same for any split.
#pragma once

#include <cstdint>
#include <string>

#include "frep/sampling/sample.h"

namespace frep {

struct BandDistanceStats {
  uint64_t haloPointEvals = 0;     // model evaluations in the halo
  uint64_t haloIntervalEvals = 0;  // interval evaluations there
};

// Replaces the evaluated values of r's leaves (a region sampled by sample(tape, grid, opt) with
// opt.bandVoxels >= 1) by the signed distance estimate, in world units (F-rep sign: positive
// inside), active where it is below the band, +-band inactive elsewhere. Signs are the
// sampled ones. Halo points are evaluated as the sampler evaluates (opt's
// extremum options); values of extremum models are functions of their point only with
// opt.pointwiseSearches, which callers set for brick-independent output.
void bandDistance(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, SampleResult& r,
                  BandDistanceStats* stats = nullptr);

// The stored value's error bound, for a file's metadata and a job's report.
std::string bandDistanceBound();

}  // namespace frep
