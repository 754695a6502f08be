// Internal to the extremum solver (extremum.cpp): the search objective written as a min of
// terms, with the two tools the branch-and-bound builds on it (docs/extremum.md, "Methods"):
//
//   * Constraint propagation against the cut. B&B only has to show that no point of a box gets
//     above theta = best + tolerance. With g = min_i T_i, a point where g >= theta has T_i >=
//     theta for every i; forward interval evaluation followed by backward projection of these
//     constraints through every operation (HC4-revise) shrinks a box to a box that still holds
//     all such points, and empties it when there are none. The kinks where Minkowski bodies
//     reach their maximum (both operands of the intersection active, Pasko-Minkowski eq. 3.7)
//     are exactly where natural interval bounds stay loose and where two constraints that
//     cannot both hold empty the box at once.
//   * Centred upper bounds. Natural interval bounds shrink linearly with the box; a first-order
//     (mean-value) form T(Y) in T(c) + G(Y) . (Y - c), with G(Y) an interval enclosure of the
//     (Clarke) gradient over the box computed by forward differentiation in interval
//     arithmetic, shrinks quadratically near a smooth maximum. At a kink of min_i T_i the
//     gradients of the active terms oppose each other, so a convex combination
//     sum_i l_i T_i >= min_i T_i (l_i >= 0, sum 1) whose weights cancel them (the Lagrange
//     condition of the maximum) is bounded instead. Every quantity is an outward-rounded
//     interval, so the bound is sound for any weights.
//   * Local ascent of min_i T_i (proximal bundle steps on the terms' gradients) to polish the
//     incumbent, so that the cut starts close to the true maximum.
//
// The terms: +, - and negation are distributed over the min/max below them and |a| is split into
// max(a, -a), so that each term is as smooth as the body allows; e.g. min(A(X - u), B(u)) with
// A = min(5 - |x|, ...) becomes the linear terms 5 -+ (X0 - u0), ... and B(u). R-functions are
// monotone too, but distributing them multiplies the (costly) R-function nodes: measured slower,
// so an R-function stays one term. The terms compute the body's values exactly (min, max, |a|
// and negation are exact), so g = min_i T_i also in floating point.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/evaluators/interval.h"

namespace frep {
namespace detail {

// e == min over the returned terms (exactly, in real arithmetic); at most kMaxTerms.
std::vector<Expr> minTerms(const Expr& e);
// e == max over the returned terms.
std::vector<Expr> maxTerms(const Expr& e);
constexpr size_t kMaxTerms = 12;

class TermForm {
 public:
  // objective: over x[0..n) = X and x[n..n+m) = u; uOfT: u as expressions of the p search
  // parameters t = x[n..n+p). ok() is false when the objective has nested extrema (or p = 0).
  void build(const Expr& objective, uint32_t n, uint32_t p, const std::vector<Expr>& uOfT);
  bool ok() const { return ok_; }
  size_t numTerms() const { return terms_.size(); }
  size_t numNodes() const { return nodes_.size(); }

  // The outer point X: values of the nodes that do not depend on t, once per search.
  void setX(const double* X);

  // Over t in [tlo, thi] (after setX): shrinks the box in place to a box that still holds every
  // point where all T_i >= theta; false when there is none. ub0: natural (interval) upper bound
  // of min_i T_i over the given box; ub: over the last box evaluated, which encloses the
  // returned one. passes: forward and backward walks done (each costs about one interval
  // evaluation of the body). theta = +inf: forward evaluation only.
  bool contract(double* tlo, double* thi, double theta, double& ub, double& ub0, uint32_t& passes);

  // Sound upper bound of min_i T_i over t in [tlo, thi] (after setX): the smallest of every
  // term's natural and centred bounds and of the weighted combination above (its weights chosen
  // by exact line searches on a piecewise-linear surrogate). Costs one interval evaluation with
  // gradients and one at the centre.
  double upper(const double* tlo, const double* thi);

  // Values and gradients (w.r.t. t) of the terms at the point t, in double precision (search
  // directions only, never bounds). Returns min_i T_i.
  double pointGrad(const double* t);
  // min_i T_i at the point t, without gradients (double precision: a guide, never a bound).
  double pointMin(const double* t);

  // Local ascent of min_i T_i from t (in place, kept inside [lo, hi]) by proximal bundle steps;
  // stops when a step gains less than a small fraction of tol, or once min_i T_i > stopAbove.
  // Returns the number of pointGrad calls.
  uint32_t ascend(double* t, const double* lo, const double* hi, double tol,
                  double stopAbove = std::numeric_limits<double>::infinity());
  double lastAscentValue() const { return lastF_; }  // min_i T_i where ascend left t

 private:
  struct Nd {
    Op op;
    int32_t a = -1, b = -1, c = -1;
    double imm = 0.0;
    uint32_t var = 0;
    bool dep = false;     // depends on t
    bool square = false;  // x * x
  };
  // The t-dependent nodes in order, as pointGrad and evalValues walk them (operand indices
  // always valid: a missing operand reads the zero slot at index nodes_.size()).
  struct Step {
    Op op;
    bool depA = false, depB = false, square = false;
    bool constGrad = false;  // affine in t with constant coefficients: gradient set once by build
    uint32_t k = 0, a = 0, b = 0, c = 0, var = 0;
    double imm = 0.0;
  };
  std::vector<Step> steps_;
  template <uint32_t P>
  double pointGradImpl(const double* t);
  template <uint32_t P>
  [[gnu::always_inline]] inline void stepGrad(const Step& q, double a, double b, double v);
  template <uint32_t P>
  uint32_t ascendImpl(double* t, const double* lo, const double* hi, double tol, double stopAbove);
  void evalValues(const double* tlo, const double* thi);
  void evalBox(const double* tlo, const double* thi);  // values and interval gradients
  void evalCentre(const double* c);
  bool project(uint32_t k);

  uint32_t n_ = 0, p_ = 0;
  double lastF_ = 0.0;
  bool ok_ = false;
  std::vector<Nd> nodes_;          // topological order (operands first)
  std::vector<int32_t> terms_;     // node of each term
  std::vector<uint32_t> dep_, indep_;
  std::vector<uint32_t> varNode_;  // node of each parameter t_j (UINT32_MAX: unused)
  std::vector<Interval> val_, valC_, der_, con_;  // over the box, at the centre, gradients, constraints
  std::vector<double> pv_, pd_, tv_, tg_;
  std::vector<double> av_, ag_, lam_, w_, t1_;  // ascent scratch
  std::vector<uint32_t> sel_;
  std::vector<double> pairD_, pairDD_;
  std::vector<char> pairDone_;
  std::vector<double> cbuf_, Gl_, Gh_, vv_, clam_, H_, L_;  // upper() scratch
  std::vector<Interval> Dv_;
  std::vector<uint32_t> csel_;
};

}  // namespace detail
}  // namespace frep
