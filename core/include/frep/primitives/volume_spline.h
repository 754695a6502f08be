// Volume splines (Pasko-Survey: deformation by algebraic sums, reconstruction from scattered
// points): the field through given values at scattered centres,
//
//   f(X) = sum_i l_i |X - c_i|^3 + p0 + p . X                       (the r^3 volume spline)
//        + sum_j m_j phi(|X - c_j| / rho),  phi(t) = (1 - t)^4 (4t + 1) for t < 1, else 0,
//
// interpolating f(c_i) = v_i at every centre.
//
// Fit (once, when the model is compiled). Up to kMaxDense centres the spline is the standard r^3
// interpolant alone: the saddle-point system [A P; P^T 0] [l; p] = [v; 0] (A_ij = |c_i - c_j|^3,
// P = [1 c_i]) solved densely with LU and partial pivoting, O(n^3) time and 8 n^2 bytes
// (2000 centres: 32 MB, about a second). Past that, the dense level is fitted through an evenly
// strided subset of kMaxDense centres and the residuals at all n centres are interpolated by the
// compactly supported Wendland function phi (positive definite in 3D), a sparse symmetric
// positive definite system solved by sparse Cholesky (LDL^T, AMD ordering), with rho chosen so
// that a centre has about 40 neighbours: O(n) memory and, for centres sampled from a surface,
// near O(n^1.5) time. Coordinates are normalised to the centres' bounding box first. At most
// kMaxCentres centres; coincident centres, fewer than four not on one plane, and a system the
// solvers cannot satisfy to 1e-9 relative residual are errors (std::invalid_argument).
//
// Evaluation: the dense level in one loop over centres per batch (vectorised over the points),
// the sparse level from a uniform grid of cells of size rho (only the centres within rho).
// Bounds: per centre, the exact range of |X - c| over the box (a point-to-box distance) gives the
// exact range of each term (r^3 increasing, phi decreasing), summed and widened by a bound on
// the rounding error of the sum.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "frep/expressions/field_function.h"

namespace frep {

using Point3 = std::array<double, 3>;

class VolumeSpline final : public FieldFunction {
 public:
  static constexpr size_t kMaxDense = 2000;
  static constexpr size_t kMaxCentres = 200000;

  // Throws std::invalid_argument with the reason (and the centres concerned). Fits of the same
  // data in one process share one object (a cache of the live ones).
  static std::shared_ptr<const VolumeSpline> fit(const std::vector<Point3>& centres,
                                                 const std::vector<double>& values);

  size_t numCentres() const { return centres_.size(); }
  size_t numDense() const { return dense_.size(); }
  double supportRadius() const { return rho_ * scale_; }  // 0 when there is no sparse level
  double maxResidual() const { return maxResidual_; }     // max |f(c_i) - v_i| after the fit

  std::string describe() const override;
  uint64_t contentHash() const override { return hash_; }
  bool sameContent(const FieldFunction& other) const override;
  double value(const double p[3]) const override;
  void values(const double* u, const double* v, const double* w, double* out, size_t n) const override;
  double gradient(const double p[3], double g[3]) const override;
  Interval bound(const Interval box[3]) const override;

 private:
  struct Term {  // a centre in normalised coordinates and its coefficient
    double x, y, z, w;
  };
  VolumeSpline() = default;
  static std::shared_ptr<VolumeSpline> solve(const std::vector<Point3>& centres, const std::vector<double>& values);
  double denseValue(const double q[3]) const;
  double sparseValue(const double q[3]) const;
  template <typename Fn>
  void forSparseNear(const double lo[3], const double hi[3], Fn&& fn) const;

  std::vector<Point3> centres_;  // as given (for sameContent and the fit cache)
  std::vector<double> values_;
  double origin_[3] = {0, 0, 0}, scale_ = 1.0;  // q = (X - origin) / scale
  std::vector<Term> dense_;      // l_i at c_i
  double poly_[4] = {0, 0, 0, 0};  // p0 + p . q
  std::vector<Term> sparse_;     // m_j at c_j, sorted by grid cell
  double rho_ = 0.0;             // support radius (normalised); 0: no sparse level
  double gridLo_[3] = {0, 0, 0}, cellSize_ = 1.0;
  int cells_[3] = {0, 0, 0};
  std::vector<uint32_t> cellStart_;  // sparse_[cellStart_[k] .. cellStart_[k + 1]) lie in cell k
  double maxResidual_ = 0.0;
  uint64_t hash_ = 0;
};

// Surface points with outward normals to interpolation data for reconstruction (Pasko-Survey,
// reconstruction from scattered points): each point with value 0, and off-surface points at
// p - eps n (value +eps, inside) and p + eps n (value -eps, outside), so that the spline
// approximates the signed distance near the surface, positive inside. Normals need not be
// unit (zero normals are an error). Output order: surface points, then outer, then inner.
void offSurfacePoints(const std::vector<Point3>& points, const std::vector<Point3>& normals, double eps,
                      std::vector<Point3>& centres, std::vector<double>& values);

}  // namespace frep
