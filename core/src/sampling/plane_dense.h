// Internal to core: evaluatePlane's path for tapes of the arithmetic subset (DenseTape::supports,
// frep/expressions/dense_tape.h), with the same results as the general path (plane.cpp): values
// bit-identical to the full tape, sign images with the double path's signs.
#pragma once

#include <vector>

#include "frep/sampling/plane.h"

namespace frep {

// out: lattice.width * lattice.height values (sized by the caller); stats: the sums over all
// threads (zeroed by the caller).
void evaluatePlaneDense(const TapePtr& tape, const PlaneLattice& lattice, const PlaneOptions& options,
                        std::vector<double>& out, PlaneStats& stats);

}  // namespace frep
