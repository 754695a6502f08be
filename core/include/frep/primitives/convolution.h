// Convolution surfaces with the kernels of Vyatkin-Perturbation eq. 1-6 over the skeletons the
// paper lists for eq. 7 (points, segments, arcs, triangles, planes): the field
//
//   f(X) = sum_i  integral over skeleton element i of  h(S_i |X - s|) ds        (eq. 9)
//
// with ds the element's measure (1 for a point, arc length, area), S_i the element's width
// factor (the kernel is evaluated at S r, as the Cauchy kernel's s in eq. 7) and h one of
//   Gauss          exp(-q^2)                                                   eq. 1 (a = S)
//   Inverse        1 / q                                                       eq. 2
//   InverseSquare  1 / q^2                                                     eq. 3
//   Metaball       1 - 3 q^2 (q <= 1/3), 3/2 (1 - q)^2 (q <= 1), 0             eq. 4 (Nishimura)
//   Soft           1 - 22/9 q^2 + 17/9 q^4 - 4/9 q^6 = (1 - q^2)^2 (9 - 4 q^2) / 9 (q < 1), 0
//                  (Wyvill's soft objects; eq. 5 as printed has -1/9 and -23/9, which is not 0
//                  at q = 1 -- a misprint -- so the published Wyvill coefficients are used)
//   Quartic        (1 - q^2)^2 (q < 1), 0                                      eq. 6 (W-shaped)
// Every kernel is non-increasing in q >= 0 and non-negative, which gives the interval bounds.
//
// Integration (the value), per skeleton:
//   point     closed form h(S |X - c|) for every kernel.
//   segment   closed forms: Gauss via erf/erfc, Inverse via asinh/log, InverseSquare via atan2;
//             Quartic, Soft and the inner Metaball piece are polynomials in the arc-length
//             parameter on the segment clipped to the support, integrated exactly by 4-point
//             Gauss-Legendre (exact to degree 7; the kernels have degree <= 6); the outer Metaball
//             piece 3/2 (1 - S r)^2 by its antiderivative (with u sqrt(d^2+u^2) + d^2 asinh(u/d)).
//   plane     closed forms 2 pi / S^2 * int_{S|h|}^inf h(q) q dq (h the distance to the plane)
//             for Gauss, Metaball, Soft, Quartic; Inverse and InverseSquare diverge over a plane
//             (the paper's note under eq. 3) and are refused.
//   triangle  exact radial integral (the same tails as the plane) in fans from the foot of the
//             perpendicular to each edge, then the fan angle numerically: adaptive bisection with
//             10-point Gauss-Legendre, split at the support's kinks, a panel accepted when it
//             agrees with its two halves to 1e-13 relative (an estimate, not a proof; the tests
//             check 1e-9 against an independent Gauss-Kronrod reference).
//   arc       the arc-length integral by the same adaptive Gauss-Legendre, split at the nearest
//             point's angle and the support's kinks.
// Gradient: the same computation in forward-mode dual numbers (derivative of the computed value).
//
// Bounds (sound): each element is cut into pieces (1 point, 8 sub-segments, 8 sub-arcs, 16
// sub-triangles) with bounding spheres; over a box, the distance from any point of a piece to
// any point of the box lies in [max(0, dist(box, centre) - radius), maxdist(box, centre) +
// radius], so the element's field lies in sum_pieces measure * [h(S dmax), h(S dmin)]. Planes
// bound exactly from the range of |h|. value() is clamped into the same bound at the point
// itself (a zero-width box), which only moves rounding noise, so a box bound encloses every point
// value in it (the bound's floating-point operations are monotone in the box).
// Segment and arc boxes smaller than a piece (where that bound stops shrinking: renders would
// show a fat surface) also get the value at the box's centre +- a slope bound (sum of measure * S * sup |h'| beyond
// each piece's nearest distance) times the half-diagonal, with a margin for the value's error.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "frep/expressions/field_function.h"

namespace frep {

enum class ConvKernel { Gauss, Inverse, InverseSquare, Metaball, Soft, Quartic };
enum class ConvSkeleton { Point, Segment, Arc, Triangle, Plane };

const char* convKernelName(ConvKernel k);      // "Gauss", "Inverse", ...
const char* convSkeletonName(ConvSkeleton s);  // "Point", "Segment", ...
// The kernel h(q) itself (eq. 1-6), q >= 0.
double convKernelValue(ConvKernel k, double q);

// One skeleton element and its width factor S (> 0). Geometry by skeleton:
//   Point    {cx, cy, cz}
//   Segment  {bx, by, bz, ex, ey, ez}
//   Arc      {cx, cy, cz, ux, uy, uz, vx, vy, vz, r, theta}: the points c + r (cos t u + sin t v),
//            0 <= t <= theta (radians, 0 < theta <= 2 pi), u and v orthonormal
//   Triangle {ax, ay, az, bx, by, bz, cx, cy, cz}
//   Plane    {px, py, pz, nx, ny, nz}: through p with normal n (any length but non-zero)
struct ConvElement {
  std::vector<double> geometry;
  double S = 1.0;
};

class Convolution final : public FieldFunction {
 public:
  // Throws std::invalid_argument for bad elements (S <= 0, a degenerate segment or triangle, a
  // zero normal, a non-orthonormal arc frame) and for Inverse/InverseSquare over planes.
  static std::shared_ptr<const Convolution> make(ConvKernel kernel, ConvSkeleton skeleton,
                                                 std::vector<ConvElement> elements);

  ConvKernel kernel() const { return kernel_; }
  ConvSkeleton skeleton() const { return skeleton_; }
  size_t size() const { return elements_.size(); }

  std::string describe() const override;
  uint64_t contentHash() const override { return hash_; }
  bool sameContent(const FieldFunction& other) const override;
  double value(const double p[3]) const override;
  double gradient(const double p[3], double g[3]) const override;
  Interval bound(const Interval box[3]) const override;

  // One element's value without the clamp into its bound (for tests of the integration).
  double rawElementValue(size_t i, const double p[3]) const;

 private:
  struct Piece {  // a bounding sphere of part of an element and that part's measure
    double c[3], radius, measure;
  };
  Convolution() = default;
  void elementBound(size_t i, const double lo[3], const double hi[3], double& outLo, double& outHi) const;

  ConvKernel kernel_ = ConvKernel::Gauss;
  ConvSkeleton skeleton_ = ConvSkeleton::Point;
  std::vector<ConvElement> elements_;
  std::vector<std::vector<Piece>> pieces_;  // per element (not planes)
  double largestPiece_ = 0.0;               // the largest piece radius (bound())
  uint64_t hash_ = 0;
};

}  // namespace frep
