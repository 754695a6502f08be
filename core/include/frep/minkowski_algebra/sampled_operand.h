// An operand with no exact form, replaced by the closed mesh of its surface, so that a Minkowski
// sum or difference with a ball or a convex polytope takes the exact paths (distance_offset.h,
// mesh_convex_sum.h) instead of the per-point search: frMinkowski's method 2 (docs/language.md).
//
// The operand is meshed on a res^3 grid over its box (grown by two voxels so the surface is
// inside) and simplified within half a voxel. Every point of that mesh lies within the larger of
// rawMeshErrorBound (chords and roots, mesh.h) and the simplifier's certified bound of the
// operand's surface; the sum of the mesh's solid is then within that distance of
// the true sum wherever the mesh follows the surface (a feature thinner than a voxel can be
// missed: a sampled operand, not a certified one). The bound is carried by the mesh field
// (FieldFunction::setErrorBound) into the job's surface_error_bound and its report line.
#pragma once

#include <optional>
#include <string>

#include "frep/expressions/expr.h"
#include "frep/extremum/extremum.h"

namespace frep::minkowski {

struct SampledOperand {
  Expr field;           // the exact signed distance of the mesh's solid, at x[0..2]
  double errorBound = 0;
  size_t triangles = 0;
  int res = 0;
};

// The sampled operand of a (3 coordinates, no parameters) over box, or nothing when the mesh is
// empty or not closed (the solid leaves the box). Throws std::invalid_argument for res outside
// [8, 1024].
std::optional<SampledOperand> sampleOperand(const Expr& a, const Bounds& box, int res, const std::string& name);

}  // namespace frep::minkowski
