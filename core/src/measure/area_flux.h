// Internal to mass_properties.cpp: bounds on the surface area of a solid from the boundary
// leaves of the octree, by the flux form of the divergence theorem.
//
// In a cell A with a unit vector n, the region R = solid ∩ A has outward normal nu, so
//     0 = integral over dR of n . nu = -Phi_A + sum over the faces F of A of (n . nu_F) a_F,
// where a_F is the area of solid ∩ F and Phi_A = -integral over the surface in A of n . nu.
// Always Phi_A <= area_A; and when every normal of the surface in A is within angle theta of
// n (the gradient cone), area_A <= Phi_A / cos theta. So
//     sum_A Phi_A <= area <= sum_A Phi_A + sum_A (sec theta_A - 1) Phi_A,
// and sum_A Phi_A = sum over face pieces P of (sum of n_A . nu_F over the cells A on either
// side of P) a_P. Two neighbouring boundary leaves see a shared piece with opposite nu_F and
// nearly equal n, so its coefficient is O(h) and the uncertainty of a_P (O(h^3), from the
// cells' planes on the face) counts O(h^4) per piece: the bound is second order, where bounding
// each cell's shadow separately loses O(h^3) per cell along the rim of every cell (first order).
#pragma once

#include <vector>

#include "frep/evaluators/interval.h"
#include "measure/box_clip.h"

namespace frep::measure_detail {

struct AreaCell {
  double lo[3], hi[3];
  HalfSpace L, U;       // over y = x - centre: L <= f <= U on the cell
  double n[3];          // unit vector (all 0: none, the cell adds nothing to the lower bound)
  double coneExcess;    // (sec theta - 1) * upper bound of Phi; +inf: no cone
  double shadowLo;      // a lower bound of this cell's area by itself
  double faceLo[6], faceHi[6];  // faceBounds: per face 2 * axis + side
};

// Bounds from the cell's planes on the area of solid ∩ each of its faces (fills faceLo/faceHi).
void faceBounds(AreaCell& c);

struct AreaTotals {
  double lower = 0, upper = 0;        // the surface inside the box
  double capLower = 0, capUpper = 0;  // solid ∩ the box's faces, from these cells
  unsigned capMask = 0;               // outer faces (bit 2 * axis + side) with capUpper > 0
};

// widths (optional): each cell's share of upper - lower, for the refinement's choice.
AreaTotals surfaceArea(const std::vector<AreaCell>& cells, const Interval box[3], std::vector<double>* widths,
                       int threads);

}  // namespace frep::measure_detail
