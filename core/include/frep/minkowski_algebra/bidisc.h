// The bidisc of Roerdink-Minkowski §IV.B (the sum of two perpendicular flat discs, Fig. 5) and
// block ⊕ bidisc, as a closed-form F-rep and as ray-tracer primitives (bicircles R9–R11,
// cylinders, blocks; Theorem 5).
//
// Canonical frame: disc A of radius a normal to x (in the yz plane), disc B of radius b normal
// to y (in the xz plane); z is the axis the two discs share. A point X lies in A ⊕ B iff some
// split z = z1 + z2 puts (y, z1) in A and (x, z2) in B, so
//
//   G(X) = max over t of min(a − |(y, t)|, b − |(x, z − t)|)
//
// is >= 0 exactly on the bidisc and 1-Lipschitz (a max of minima of 1-Lipschitz functions); it
// is the largest v with X ∈ xdisc(a − v) ⊕ ydisc(b − v). The two terms are monotone on t ∈
// [0, |z|], so the max is at an end or where they cross, and the crossing value solves a
// quadratic (bidiscGauge). With a block [0, L] the sum is {X : G(e(X)) >= 0}, e the excess of X
// over the block per axis (the bidisc is symmetric in every coordinate plane and convex, so G
// falls in each |e_i| and the block's best point is X clamped to it); G ∘ e is 1-Lipschitz too.
// Its zero set is exact (error bound 0); the value is not the Euclidean distance.
//
// There is no closed form once a sphere or a third disc axis joins (the bicircle-sphere,
// tricircle and tricircle-sphere surfaces R12–R16 have degree above four, §IV.E): such sums take
// the convex-projection distance of disc_sum_distance.h.
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

// G at the excess (u, w, h) = (|e_x|, |e_y|, |e_z|) >= 0 in the canonical frame.
double bidiscGauge(double u, double w, double h, double a, double b);
Expr bidiscGauge(const Expr& u, const Expr& w, const Expr& h, double a, double b);

// The quartic P with {P <= 0} = the bicircle solid of the canonical bidisc centred at the
// origin: P = (x² − y² + z² + a² − b²)² − 4 z² (a² − y²) = Π (z ± α ± β), α = √(a² − y²),
// β = √(b² − x²) (Roerdink-Minkowski §IV.B's bicircle equation, axes renamed). {P <= 0} is the
// shell between |z| = |α − β| and α + β (empty outside |x| <= b, |y| <= a); the bidisc is that
// shell plus the x-cylinder of radius a over |x| <= b and the y-cylinder of radius b over |y| <= a.
double bicirclePolynomial(double x, double y, double z, double a, double b);
// Its coefficients c[i][j][k] of x^i y^j z^k (i + j + k <= 4), for the POV-Ray writer.
struct QuarticTerm {
  int i, j, k;
  double c;
};
std::vector<QuarticTerm> bicircleTerms(double a, double b);

}  // namespace frep::minkowski
