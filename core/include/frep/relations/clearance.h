// Certified clearance (minimum distance) and penetration depth of two solids f >= 0, with
// witnesses (issue 33; Pasko-Survey, relations; Vyatkin-Perturbation, "Collision detection":
// recursive subdivision with interval bounds). Both are enclosed: lower <= true value <= upper.
#pragma once

#include <cstdint>
#include <vector>

#include "frep/evaluators/interval.h"
#include "frep/expressions/expr.h"
#include "frep/expressions/tape.h"

namespace frep {

struct ClearanceOptions {
  double tolerance = 1e-3;      // stop when upper - lower <= tolerance (absolute)
  double minSize = 0.0;         // smallest box edge split (0: tolerance / 16)
  uint64_t maxPairs = 4000000;  // budget of box pairs examined
};

// dist(A ∩ box, B ∩ box) = min |p - q| over p in A, q in B, both in the box (n intervals).
// Branch and bound over pairs of boxes, nearest pair first: a pair's lower bound is the
// distance between its boxes (kept while both may hold points of their solid); the upper bound
// is the distance of two points with fa >= 0 and fb >= 0 (box centres moved onto the surfaces by
// Newton steps). lower is 0 when the solids meet or touch.
struct ClearanceResult {
  bool emptyA = false, emptyB = false;  // no point of the solid in the box: nothing to measure
  double lower = 0.0, upper = 0.0;
  std::vector<double> a, b;  // witnesses: fa(a) >= 0, fb(b) >= 0, |a - b| = upper
  bool converged = false;    // upper - lower <= tolerance (else the budget or minSize ran out)
  uint64_t pairs = 0;        // pairs examined
};
ClearanceResult clearance(const Tape& a, const Tape& b, const Interval* box, const ClearanceOptions& options);

// Penetration depth: the shortest translation t with (A + t) and B interior-disjoint (the
// translational depth of collision detection; 0 when they do not overlap). Searched over
// translation boxes T nearest the origin first:
//   lower: every T nearer than it is proved colliding: a point a with fa(a) >= 0 and
//          fb(a + T) > 0 on the whole interval box, so a + t lies in B's interior for all t in T;
//   upper: |t| of a translation whose separation is proved by subdivision (mayIntersect says
//          Disjoint) over the box grown by t, or at first the box's narrowest width (A moved
//          out of the box); the solids are taken to lie in the box.
struct PenetrationOptions {
  double tolerance = 1e-3;  // stop when upper - lower <= tolerance
  uint64_t maxBoxes = 200000;
  int candidates = 3000;  // points of A tried as the colliding point a
};
struct PenetrationResult {
  double lower = 0.0, upper = 0.0;
  std::vector<double> translation;  // the separating t, |t| = upper
  bool converged = false;
  uint64_t boxes = 0;  // translation boxes examined
};
PenetrationResult penetration(const Expr& a, const Expr& b, uint32_t n, const Interval* box,
                              const PenetrationOptions& options);

// Moves x (n = tape.numVars() coordinates) onto the surface by Newton steps
// (projectToSurface), then inward along the gradient until f(x) >= 0; true when x ends in the
// solid and in the box.
bool settleInSolid(const Tape& tape, double* x, const Interval* box);

// Points of the solid in the box (at most about maxPoints): centres of the boxes of a uniform
// subdivision that lie in it, and centres of boundary boxes moved onto the surface (fa >= 0).
std::vector<std::vector<double>> samplePoints(const Tape& tape, const Interval* box, size_t maxPoints);

}  // namespace frep
