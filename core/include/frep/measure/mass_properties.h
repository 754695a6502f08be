// Certified mass properties of a solid f >= 0 inside a box: volume, surface area, centroid and
// inertia tensor, each as [lower, upper] (unit density), by interval integration over an
// adaptive octree (docs/measure.md).
//
// Method. A cell is inside (f > 0 on it) or outside (f < 0) when interval evaluation says so,
// and counts exactly. A cell that stays ambiguous is split while the bounds are wider than the
// tolerance; a boundary leaf gets a first-order enclosure f(x) in F(c) + G . (x - c) from
// interval gradients (the centred form; see measure/cell_affine.h), i.e. two parallel planes
// L <= f <= U with U - L = O(h^2) on a cell of size h, and
//   * volume:   box ∩ {L >= 0}  ⊆  solid ∩ box  ⊆  box ∩ {U >= 0}, both polytopes exact;
//   * moments:  the inner polytope's, plus the extreme contributions of what lies between;
//   * area:     when every gradient in G is within angle theta of n = mid G / |mid G|, the
//               surface in the cell is a graph over the plane normal to n, so its area is
//               between its shadow along n and the shadow / cos theta; the shadow holds every
//               line that crosses from {U < 0} to {L > 0} in the cell and lies within the shadow
//               of the slab {L <= 0 <= U}. A cell where no such cone exists (G near 0, a field
//               node, a jump) adds [0, +inf) until it is split small enough to have one.
// So the bounds are second-order tight: widths fall by about 4 for every level of refinement.
// The solid is measured inside the box: a solid the box cuts is measured as solid ∩ box, and the
// area then includes the cut faces (cutArea, cutFaces). Extremum nodes are measured as the exact
// operation (their certified interval bounds), not as a search's approximate value.
// Deterministic: the same numbers for any number of threads (fixed traversal, ordered sums).
// Floating-point rounding of the integration is covered by a margin (docs/measure.md).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"
#include "frep/interrupt/interrupter.h"

namespace frep {

struct MeasureBound {
  double lower = 0.0, upper = 0.0;
  double width() const { return upper - lower; }
  double mid() const { return 0.5 * (lower + upper); }
};

struct MeasureProgress {
  int round = 0;               // refinement rounds done
  uint64_t boundaryCells = 0;  // current boundary leaves
  double volumeWidth = 0.0;    // relative widths now ((upper - lower) / lower)
  double areaWidth = 0.0;
};

struct MeasureOptions {
  // Refinement stops once (upper - lower) <= tolerance * lower for the volume and the area.
  double tolerance = 0.005;
  bool areaTolerance = true;           // false: only the volume drives the refinement
  int maxDepth = 20;                   // levels below the initial grid
  uint64_t maxBoundaryCells = 2000000; // budget: stop refining beyond it (bounds stay valid)
  int initialCells = 8;                // initial grid: this many cells along the longest edge
  int threads = 0;                     // 0: all cores (the result does not depend on it)
  // Called after every round; return false to stop early (the bounds so far are valid).
  std::function<bool(const MeasureProgress&)> progress;
  const std::atomic<bool>* cancel = nullptr;  // set: stop after the current round
  // Cancelled: stop within the current round and return the last whole round's bounds (valid,
  // stopped = true); in the first round, throw Interrupted. Progress: ("measure", rounds, 0).
  // Null: the caller's.
  const Interrupter* interrupt = nullptr;
};

struct MassProperties {
  MeasureBound volume;
  MeasureBound area;     // of the boundary of solid ∩ box (cut faces included)
  MeasureBound cutArea;  // the part of it on the box's faces (0 when the box cuts nothing)
  std::array<MeasureBound, 3> centroid;
  // Inertia tensors (unit density): I_ii = integral of |y|^2 - y_i^2, I_ij = -integral of
  // y_i y_j, with y = x - centroid (inertia) or y = x (inertiaOrigin). Row-major 3x3.
  std::array<MeasureBound, 9> inertia;
  std::array<MeasureBound, 9> inertiaOrigin;
  unsigned cutFaces = 0;       // bit 2 * axis + side (side 1: the max face) the solid may reach
  bool areaBounded = true;     // false: some cell had no cone at maxDepth (area.upper = +inf)
  bool toleranceReached = false;
  bool stopped = false;        // by progress() or cancel
  int rounds = 0;
  int depth = 0;                   // deepest level reached below the initial grid
  uint64_t insideCells = 0, boundaryCells = 0;
  uint64_t firstOrderCells = 0;    // boundary leaves with a gradient enclosure
  std::string stopReason;          // why refinement ended
};

// tape: over at most 3 coordinates; box: 3 intervals.
MassProperties measureMassProperties(const TapePtr& tape, const Interval box[3], const MeasureOptions& options = {});
// The same for f over x0, x1, x2, measured through measureForm(f).
MassProperties measureMassProperties(const Expr& f, const Interval box[3], const MeasureOptions& options = {});

// A field with the same sign as f everywhere (so the same solid, boundary and interior) that
// measures better. Along the paths from the root through negation, min, max, products by
// positive constants and R-functions: an R-conjunction (disjunction) becomes min (max), which has
// its sign (the R-function's rounding of the level sets near an edge is no part of the solid but
// widens every enclosure there), and an exact box or cylinder distance
// |max(d, 0)| + min(max_k d_k, 0) becomes max_k d_k (the distance's formula kinks along every
// face, where no gradient cone exists for the area bound), and a product a b of affine factors
// whose sum is a positive constant (hfBlock's slab (x - v)(v + d - x)) becomes min(a, b).
Expr measureForm(const Expr& f);

}  // namespace frep
