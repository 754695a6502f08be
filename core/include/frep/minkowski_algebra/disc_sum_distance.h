// The exact field of block ⊕ xdisc(a) ⊕ ydisc(b) ⊕ zdisc(c) ⊕ ball(s) when no closed form exists
// (Roerdink-Minkowski Theorem 5's bicircle-sphere R12–R14, tricircle R15 and tricircle-sphere R16
// cases: discs on three axes, or on two with a sphere), by convex projection driven by support
// functions instead of a global search.
//
// Every member is convex, so the sum is (eq. 10–11). In the local frame (block [0, L]) the sum is
// {X : e(X) ∈ C}, e the excess of X over the block per axis and C = D ⊕ ball(s), D = the disc sum
// (C is symmetric in every coordinate plane; reduction.h). With q = e(X) >= 0:
//   outside D: dist(q, D) = max over unit n of n·q − h(n), h(n) = a|n_yz| + b|n_xz| + c|n_xy| the
//     support of D (support of a sum = sum of supports). Where that is positive, every local
//     maximum on the sphere is the global one, found by damped Newton in polar coordinates around
//     the nearest axis (h's cone points are there), and certified by the duality gap: every unit
//     n gives the lower bound n·q − h(n), and its support point y(n) ∈ D the upper bound
//     |q − y(n)|; they meet to rounding at the optimum. q over a flat face (the disc at
//     x = b + c, ...) is answered in closed form;
//   inside D: r·(1 − γ(q)), γ the gauge of D (γ = max over n of n·q / h(n), by Dinkelbach's
//     iteration on the same projection) and r = min h = min(a + b, a + c, b + c) (h restricted to
//     the sphere is concave in the squares of n's components, so its minimum is at an axis); it is
//     positive inside, 0 on the boundary and 1-Lipschitz (|∇γ| <= 1 / r).
// The signed distance to C is then dist − s outside D and −s − r(1 − γ) inside, so the field
// −sd_C(e(X)) is the exact Euclidean distance outside the sum, and sign-exact and 1-Lipschitz
// inside (e is 1-Lipschitz). Each value comes with a certified error bound (the remaining duality
// gap, a few ulps at convergence) that the interval bound adds to the Lipschitz bound.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "frep/geometry/field.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

// D = xdisc(r[0]) ⊕ ydisc(r[1]) ⊕ zdisc(r[2]) centred at the origin (any radii >= 0).
struct DiscSum {
  Vec3 r{0, 0, 0};
  double support(const Vec3& n) const;   // h(n), n a unit vector
  Vec3 supportPoint(const Vec3& n) const;  // a point of D where n·y = h(n)
  double inradius() const;               // min over unit n of h(n)

  // Outside D: the distance from q bracketed by the duality gap, lo <= dist <= hi. Inside (or on
  // the boundary): the gauge bracketed, gaugeLo <= γ(q) <= gaugeHi.
  struct Distance {
    double lo = 0, hi = 0;
    double gaugeLo = 0, gaugeHi = 0;
    Vec3 n{0, 0, 0};  // the last direction (unit)
    bool inside = false;
  };
  Distance distance(const Vec3& q) const;
  // max over unit m of m·q − t h(m) (= dist(q, tD) when q is outside tD) by Riemannian Newton on
  // the sphere from n (q >= 0 componentwise, m·q − t h(m) >= 0 at n); lo, hi bracket it.
  Distance maximize(const Vec3& q, double t, Vec3 n) const;
  // Signed distance of D ⊕ ball(s) at the excess q (any signs; D is symmetric) as above: the value
  // and a bound on its error.
  double signedDistance(const Vec3& q, double s, double* error) const;
};

// The field −sd_C(e(X)) of block [0, L] ⊕ D ⊕ ball(s) at local coordinates (a geometry field:
// Lipschitz interval bound widened by the evaluation's certified error).
class DiscSumField final : public DistanceField {
 public:
  DiscSumField(const Vec3& lengths, const Vec3& radii, double ball);
  std::string describe() const override;
  uint64_t contentHash() const override;
  double value(const double p[3]) const override;
  Interval bound(const Interval box[3]) const override;
  double valueWithError(const double p[3], double* error) const;

 protected:
  bool sameGeometry(const DistanceField& other) const override;

 private:
  Vec3 lengths_;
  DiscSum discs_;
  double ball_;
};

}  // namespace frep::minkowski
