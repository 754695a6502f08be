// Point membership, box classification, Newton projection and solid-solid intersection by
// recursive subdivision (Vyatkin-Perturbation, "Collision detection"; Pasko-Survey, relations).
#include "frep/relations/relations.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frep {

Membership classifyPoint(PointEvaluator& eval, const Tape& tape, const double* x, double tol) {
  const double f = eval.eval(tape, x);
  if (f > tol) return Membership::In;
  if (f >= -tol) return Membership::On;
  return Membership::Out;  // includes NaN
}

Membership classifyPoint(const Tape& tape, const double* x, double tol) {
  PointEvaluator eval;
  return classifyPoint(eval, tape, x, tol);
}

namespace {
BoxClass classOf(const Interval& v) {
  if (v.lo > 0.0) return BoxClass::Inside;
  if (v.hi < 0.0) return BoxClass::Outside;
  return BoxClass::Ambiguous;  // also NaN bounds
}
}  // namespace

BoxClass classifyBox(IntervalEvaluator& eval, const Tape& tape, const Interval* box) {
  return classOf(eval.eval(tape, box));
}

BoxClass classifyBox(const Tape& tape, const Interval* box) {
  IntervalEvaluator eval;
  return classifyBox(eval, tape, box);
}

double projectToSurface(const Tape& tape, double* x, int maxIter, double tol) {
  GradientEvaluator eval;
  const uint32_t n = tape.numVars();
  std::vector<double> g(n);
  double f = eval.eval(tape, x, g.data());
  for (int it = 0; it < maxIter && !(std::fabs(f) <= tol); ++it) {
    double g2 = 0.0;
    for (double gi : g) g2 += gi * gi;
    if (!(g2 > 0.0) || !std::isfinite(g2) || !std::isfinite(f)) break;  // no direction to step
    const double s = f / g2;
    for (uint32_t i = 0; i < n; ++i) x[i] -= s * g[i];
    f = eval.eval(tape, x, g.data());
  }
  return f;
}

IntersectionResult mayIntersect(const Tape& a, const Tape& b, const Interval* box, double minSize) {
  if (!(minSize > 0.0)) throw std::invalid_argument("mayIntersect: minSize must be > 0");
  const uint32_t n = std::max(a.numVars(), b.numVars());
  IntervalEvaluator ia, ib;
  PointEvaluator pa, pb;
  IntersectionResult result;
  bool undecided = false;
  std::vector<double> centre(n);
  // Depth-first over boxes; the lower half of each split is explored first (deterministic).
  std::vector<std::vector<Interval>> stack{std::vector<Interval>(box, box + n)};
  while (!stack.empty()) {
    std::vector<Interval> cur = std::move(stack.back());
    stack.pop_back();
    ++result.boxesVisited;
    // A box outside either solid holds no common point.
    if (ia.eval(a, cur.data()).hi < 0.0 || ib.eval(b, cur.data()).hi < 0.0) continue;
    for (uint32_t i = 0; i < n; ++i) centre[i] = cur[i].mid();
    if (pa.eval(a, centre.data()) >= 0.0 && pb.eval(b, centre.data()) >= 0.0) {
      result.contact = Contact::Intersecting;
      result.witness = centre;
      return result;
    }
    uint32_t axis = 0;
    for (uint32_t i = 1; i < n; ++i)
      if (cur[i].width() > cur[axis].width()) axis = i;
    const double lo = cur[axis].lo, hi = cur[axis].hi, mid = cur[axis].mid();
    if (!(cur[axis].width() > minSize) || mid <= lo || mid >= hi) {
      undecided = true;  // too small to split further and not decided
      continue;
    }
    std::vector<Interval> upper = cur;
    upper[axis].lo = mid;
    cur[axis].hi = mid;
    stack.push_back(std::move(upper));
    stack.push_back(std::move(cur));
  }
  result.contact = undecided ? Contact::Unknown : Contact::Disjoint;
  return result;
}

}  // namespace frep
