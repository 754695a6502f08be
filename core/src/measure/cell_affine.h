// Internal to mass_properties.cpp: a first-order (mean-value) enclosure of f over a box,
//     f(x) in F(c) + G . (x - c)   for every x in the box,
// with F(c) a sound enclosure of f at the box centre and G an interval box that holds the
// (Clarke) gradient of f at every point of the box (Lebourg's mean-value theorem; Neumaier,
// "Interval methods for systems of equations", 1990, the centred form). G comes from forward
// differentiation in interval arithmetic along the tape.
//
// Kinks. Plain forward mode takes the hull of both sides' gradients at every undecided min, max
// or |a|, so a formula whose kinks cancel (an exact box distance, |max(d, 0)| + min(max d_i, 0),
// is smooth across a face but both of its terms kink there) gets a gradient box twice as wide
// as the gradient itself: first order instead of second. Here every undecided comparison of
// two values is a switch symbol t = [x > y] (x, y identified by where their value comes from,
// so min(d, 0) and max(d, 0) share one), and derivative rows are affine in those symbols:
// max(x, y) = y + t (x - y), min(x, y) = x + t (y - x), |a| = -a + 2 [a > 0] a. At any point t
// is one number in {0, 1}, the same for every row, so sums cancel exactly (max(d, 0) + min(d, 0)
// has the row of d) and the box of the final row, t in [0, 1], still holds every gradient.
// A square root of a sum of squares (a Euclidean norm) gets the norm's rule, sum_k (m_k / |m|)
// grad m_k with |m_k / |m|| <= 1, which stays finite where the norm vanishes.
//
// Not differentiable across the box (a floor that jumps, an undecided select or comparison, a
// field node, sqrt or log at 0): the enclosure fails and the caller falls back to the value
// interval alone (zero order).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"

namespace frep::measure_detail {

constexpr int kMaxSwitches = 16;

// A derivative row over the seed directions (3: the outer x, y, z), affine in switch symbols.
struct Row {
  Interval g[3];
  int n = 0;
  uint32_t sym[kMaxSwitches];
  Interval s[kMaxSwitches][3];
  bool zero = true;  // identically 0 (no switch terms)
  // Filled by CellAffineEvaluator::gradient for its result: a symbol is a switch or a product of
  // switches (t t' stands for their product); term j is 1 exactly when all the base switches in
  // mask[j] are. The gradients are then R0 + sum_j [mask_j ⊆ b] R_j over base assignments b, a
  // multilinear image of the cube [0, 1]^nBase, so linear and convex functions of them are
  // extreme at its 2^nBase vertices.
  int nBase = 0;
  uint32_t mask[kMaxSwitches] = {};
};

class CellAffineEvaluator {
 public:
  CellAffineEvaluator();
  ~CellAffineEvaluator();
  CellAffineEvaluator(const CellAffineEvaluator&) = delete;
  CellAffineEvaluator& operator=(const CellAffineEvaluator&) = delete;

  // Sound enclosure of f at the point x (extremum nodes: their certified bound at the point).
  Interval valueAt(const Tape& tape, const double* x);
  // Value enclosure over the box and a gradient box; false when f may not be Lipschitz on the
  // box (grad then undefined). box: tape.numVars() intervals (3).
  bool gradient(const Tape& tape, const Interval* box, Interval grad[3], Interval* value = nullptr, Row* row = nullptr);

  // Generalised walk (extremum bodies): the vars' values and their seed rows (3 directions).
  // Returns false when the result's row is not finite; out: the result's row collapsed to a box.
  bool walk(const Tape& tape, const Interval* vars, const Row* seeds, bool rows, Interval* value, Interval out[3]);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frep::measure_detail
