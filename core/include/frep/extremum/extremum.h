// The extremum node: f(X) = max (or min) over hidden variables u in a domain D of a body g(X, u).
//
// It expresses the papers' global operations as one node (docs/extremum.md):
//   projection (u = the dropped coordinates; Pasko-Minkowski eq. 4.2-4.4, Vyatkin-Perturbation
//   eq. 13-15), Minkowski sum (g = A(X - u) & B(u); Pasko-Minkowski eq. 3.2-3.6), Minkowski
//   difference, sweep by a moving solid (u = t; Pasko-Survey, sweeping), constant-radius offset
//   (u in a ball or on a sphere; Pasko-Survey, third offset) and metamorphosis (eq. 4.5).
//
// Variable spaces. The body is written in its OWN variable space: x[0..n) are the outer point X
// and x[n..n+m) the hidden u. The node's children are the n outer expressions X_i (over the
// outer model's variables), stored in spec->inputs; remap()/bindParams() of the outer model
// rewrite only these inputs, never the body, so indices never clash. The body must not contain
// parameters (bind them before building the spec).
//
// Two search methods, both with a stated error:
//   Grid: the paper's eps-grid over the domain's parameters plus quadratic refinement along each
//     axis (eq. 4.3-4.4). Values are real body values, so f_grid <= f; with grid covering radius
//     delta = sqrt(p)/2 * eps (p parameters) and an L-Lipschitz body, f - f_grid <= L * delta,
//     which gives the paper's inclusion A_delta + B_delta in M in A + B for Minkowski sums.
//   BranchAndBound: interval branch-and-bound over the parameters: boxes whose interval upper
//     bound cannot beat the best value found (plus tolerance) are dropped; it stops when the
//     certified gap <= tolerance and reports [lo, hi] with lo <= f <= hi (or says it could not
//     certify within maxBoxes). On the body written as a min of terms, the incumbent is
//     polished by local ascent, boxes are contracted against the cut (best + tolerance) by
//     interval constraint propagation, and small boxes also get a centred (mean-value) bound
//     with interval gradients (docs/extremum.md, "Methods and their error").
// For Min the same searches run on -g.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"

namespace frep {

enum class ExtremumKind : uint8_t { Max, Min };
enum class ExtremumMethod : uint8_t { Grid, BranchAndBound };
// Box: u in [lo, hi] (m parameters = u). Sphere: |u| = radius (m - 1 angle parameters, m >= 2).
// Ball: |u| <= radius (m parameters: rho in [0, radius] and m - 1 angles).
enum class DomainKind : uint8_t { Box, Sphere, Ball };

struct ExtremumSpec {
  ExtremumKind kind = ExtremumKind::Max;
  Expr body;                 // over x[0..n) = X and x[n..n+m) = u
  std::vector<Expr> inputs;  // the n outer expressions X_0..X_{n-1}
  uint32_t hidden = 0;       // m
  DomainKind domain = DomainKind::Box;
  std::vector<double> lo, hi;  // Box: bounds of each hidden variable (size m)
  double radius = 0.0;         // Sphere / Ball
  ExtremumMethod method = ExtremumMethod::BranchAndBound;
  double eps = 0.05;         // Grid: step in parameter units (angles: arc length at `radius`)
  double tolerance = 1e-3;   // BranchAndBound: certified gap (absolute, in units of g)
  uint32_t maxBoxes = 20000; // BranchAndBound: per-point budget of box splits
  uint32_t intervalBudget = 24;  // interval evaluator: body interval evaluations per X box

  uint32_t outer() const { return static_cast<uint32_t>(inputs.size()); }
  uint32_t numParams() const;  // p: dimension of the searched parameter box
};

// Checks the spec (sizes, bounds, eps/tolerance > 0, no parameters in the body) and returns the
// node. Throws std::invalid_argument with the offending field.
Expr extremum(ExtremumSpec spec);

// Certified result of one search at one point X.
struct ExtremumResult {
  double value = 0.0;         // the extremum found (a real body value: max: <= true max)
  double lo = 0.0, hi = 0.0;  // interval certified to contain the true extremum (B&B; Grid: -inf/+inf side open)
  bool certified = false;     // B&B stopped with gap <= tolerance
  bool signDecided = false;   // a sign-only search that stopped once its sign was certain (solveSign)
  std::vector<double> u;      // the arg-extremum (hidden variables)
  std::vector<double> t;      // ... as search parameters (angles for Sphere/Ball): a warm start
  uint64_t pointEvals = 0, intervalEvals = 0;  // body evaluations spent
};

// Search engine for one spec and its compiled body (used by every evaluator for Op::Extremum,
// also usable directly). One solver per thread.
class ExtremumSolver {
 public:
  ExtremumSolver(std::shared_ptr<const ExtremumSpec> spec, TapePtr body);
  ~ExtremumSolver();
  const ExtremumSpec& spec() const { return *spec_; }

  // The spec's method. warmT: a previous result's t (numParams() values) to start from, or null.
  ExtremumResult solve(const double* X, const double* warmT = nullptr);
  // A cold solve(X) cut short once the sign of its value is known: the value returned has the
  // same sign bit as solve(X).value (for the mesher's signs), but it may be further from the
  // extremum (certified is then false). Much cheaper away from the zero set.
  ExtremumResult solveSign(const double* X);
  ExtremumResult solveGrid(const double* X);
  ExtremumResult solveBranchAndBound(const double* X, const double* warmT = nullptr);
  // Sound enclosure of the extremum over an X box (interval evaluator). signOnly: stop as soon
  // as the sign is decided (classification); otherwise refine for a tight upper bound.
  // budgetOnly: stop at intervalBudget evaluations (no continuation for boxes whose bound is
  // much wider than the X box explains).
  Interval bound(const Interval* Xbox, bool signOnly = true, bool budgetOnly = false);
  // Danskin: value and d f / d X_i = d g / d X_i at the arg-extremum (grad: n values).
  double gradient(const double* X, double* grad);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::shared_ptr<const ExtremumSpec> spec_;
};

// Process-wide counters (relaxed atomics, updated once per search) for benches and reports.
// uncertified counts B&B searches that stopped at maxBoxes before their gap reached the
// tolerance (widestGap: the widest gap one of them left); signDecided counts sign-only searches
// that stopped once their sign was certain (their sign is certified, not their value).
struct ExtremumCounters {
  std::atomic<uint64_t> searches{0}, pointEvals{0}, intervalEvals{0}, uncertified{0}, signDecided{0};
  std::atomic<double> widestGap{0.0};
  std::atomic<uint64_t> boundCalls{0}, boundIntervalEvals{0};
};
ExtremumCounters& extremumCounters();
void resetExtremumCounters();

// ---- Builders --------------------------------------------------------------------------
// Operand bounding boxes must be given by the caller (the language layer will compute them);
// a box that does not contain the operand's solid gives a wrong (too small) result.

struct Bounds {
  std::vector<double> lo, hi;
};

struct SearchOptions {
  ExtremumMethod method = ExtremumMethod::BranchAndBound;
  double eps = 0.05;        // Grid step
  double tolerance = 1e-3;  // B&B gap
  uint32_t maxBoxes = 20000;
  uint32_t intervalBudget = 24;
  // Search the operands in their min/max form (frep/expressions/min_max_form.h): the same set,
  // searched as fast as if it had been written with min/max; the node's value is then that of
  // the min/max form. false: the operands' R-functions as written (slower, same set).
  bool minMaxOperands = true;
};

struct MinkowskiOptions : SearchOptions {
  // R-intersection parameter of g = A(X - u) &_a B(u) (ops.h rIntersection): a = 1 (min, the
  // default) keeps the set exact and the body 1-Lipschitz for distance operands; a = 0 is the
  // paper's eq. 3.3 (then unit ball + unit ball gives exactly 4 - |X|^2, eq. 4.1).
  double a = 1.0;
  // Analytic shortcut: A is an exact signed distance (positive inside) and B is the ball
  // ballRadius around ballCenter: the sum is A(X - c) + r (no search).
  bool aIsDistance = false;
  bool bIsBall = false;
  std::vector<double> ballCenter;
  double ballRadius = 0.0;
};

// A + B over n coordinates: max over u in boundsB of A(X - u) &_a B(u) (Pasko-Minkowski eq.
// 3.5-3.6 with the roles named so that the search runs over the smaller operand B).
Expr minkowskiSum(const Expr& A, const Expr& B, uint32_t n, const Bounds& boundsB,
                  const MinkowskiOptions& options = {});
// Ball (r1, c1) + ball (r2, c2) = ball (r1 + r2, c1 + c2), as r^2 - |X - c|^2 (exact, no search).
Expr minkowskiBalls(const std::vector<double>& c1, double r1, const std::vector<double>& c2, double r2);
// Erosion A - B = {X : X + B in A} = min over u in boundsB of max(A(X + u), -B(u)) (for a
// symmetric B this equals the classical difference with the reflected B).
Expr minkowskiDifference(const Expr& A, const Expr& B, uint32_t n, const Bounds& boundsB,
                         const SearchOptions& options = {});
// Projection of A (over N = numVars coordinates, or more via totalDims) along the coordinates
// `hiddenDims` (ranges in `box`): max over them; the result uses the remaining coordinates in
// their order, renumbered from 0.
Expr project(const Expr& A, uint32_t totalDims, const std::vector<uint32_t>& hiddenDims,
             const Bounds& box, const SearchOptions& options = {});

// A rigid motion in 2D or 3D given as expressions of t = x[0]: the moving solid at time t is
// {R(t) Y + T(t) : Y in A}, R = Rz(rotation[2]) Ry(rotation[1]) Rx(rotation[0]) in 3D, R =
// rotation by rotation[0] in 2D. Missing entries are 0.
struct Motion {
  std::vector<Expr> translation;
  std::vector<Expr> rotation;
};
// Sweep: max over t in [t0, t1] of A(M(t)^-1 X) (Pasko-Survey). A may use x[n] as t (a shape
// that changes while it moves).
Expr sweep(const Expr& A, uint32_t n, const Motion& motion, double t0, double t1,
           const SearchOptions& options = {});

// Constant-radius offset: r > 0 grows (max over |u| <= r of A(X + u)), r < 0 shrinks (min).
// surfaceOnly: search the sphere |u| = |r| only (Pasko-Survey's form; one parameter fewer, but
// it misses components of A, or holes, smaller than the ball). r = 0 returns A.
Expr offsetRadius(const Expr& A, uint32_t n, double r, const SearchOptions& options = {},
                  bool surfaceOnly = false);

// Metamorphosis (Pasko-Minkowski eq. 4.5): ((1 - t) A) + (t B), t in [0, 1]; t = 0 gives A and
// t = 1 gives B exactly. Bounds are those of the unscaled operands.
Expr morphMinkowski(const Expr& A, const Expr& B, uint32_t n, double t, const Bounds& boundsB,
                    const MinkowskiOptions& options = {});

}  // namespace frep
