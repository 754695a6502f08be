// Relations between points, boxes and solids (Pasko-Survey: relations; Vyatkin-Perturbation:
// relations and collision detection by recursive space subdivision). A solid is f >= 0.
#pragma once

#include <cstdint>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"

namespace frep {

// Point membership with a tolerance band around the surface: In (f > tol), On (|f| <= tol),
// Out (f < -tol). A NaN value (domain error) is Out.
enum class Membership { Out, On, In };
Membership classifyPoint(const Tape& tape, const double* x, double tol);
Membership classifyPoint(PointEvaluator& eval, const Tape& tape, const double* x, double tol);

// Box classification by interval evaluation (box: tape.numVars() intervals). Inside: f > 0 on
// the whole box (it lies in the solid's interior); Outside: f < 0 on the whole box (disjoint
// from the closed solid); Ambiguous otherwise, including where f may be undefined.
enum class BoxClass { Outside, Ambiguous, Inside };
BoxClass classifyBox(const Tape& tape, const Interval* box);
BoxClass classifyBox(IntervalEvaluator& eval, const Tape& tape, const Interval* box);

// Newton projection onto the surface f = 0: x <- x - f grad / |grad|^2, in place, until
// |f| <= tol, the gradient vanishes or maxIter steps. Returns f at the final x.
double projectToSurface(const Tape& tape, double* x, int maxIter = 20, double tol = 1e-12);

// Intersection (collision) of two solids inside a box, by recursive bisection of the box along
// its longest edge. The box has max(a.numVars(), b.numVars()) intervals.
//   Disjoint:     every sub-box was proved outside one of the solids, so A ∩ B ∩ box = ∅.
//   Intersecting: witness is a point of the box where fa >= 0 and fb >= 0 (a box centre).
//   Unknown:      neither could be shown down to sub-boxes of longest edge <= minSize
//                 (typical for solids that only touch, or for near misses finer than minSize).
enum class Contact { Disjoint, Intersecting, Unknown };
struct IntersectionResult {
  Contact contact = Contact::Unknown;
  std::vector<double> witness;  // set when Intersecting
  uint64_t boxesVisited = 0;    // interval evaluations pairs performed
};
IntersectionResult mayIntersect(const Tape& a, const Tape& b, const Interval* box, double minSize);

}  // namespace frep
