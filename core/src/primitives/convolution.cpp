// Convolution kernels x skeletons (Vyatkin-Perturbation eq. 1-7, 9): values, gradients, bounds.
// The methods and their accuracy are described in frep/primitives/convolution.h.
#include "frep/primitives/convolution.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "primitives/convolution_kernels.h"

namespace frep {

namespace {

using conv_detail::kInf;
using conv_detail::kPi;
using conv_detail::kernelAt;
using conv_detail::norm;
using conv_detail::planeOf;

// Signed distance to the plane, term by term in a fixed order (the bound repeats it).
double planeTerm(const double* g, double nl, int i, double x) { return (x - g[i]) * (g[3 + i] / nl); }

uint64_t mixBits(uint64_t h, double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return h ^ (b + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

}  // namespace

const char* convKernelName(ConvKernel k) {
  switch (k) {
    case ConvKernel::Gauss: return "Gauss";
    case ConvKernel::Inverse: return "Inverse";
    case ConvKernel::InverseSquare: return "InverseSquare";
    case ConvKernel::Metaball: return "Metaball";
    case ConvKernel::Soft: return "Soft";
    case ConvKernel::Quartic: return "Quartic";
  }
  return "?";
}

const char* convSkeletonName(ConvSkeleton s) {
  switch (s) {
    case ConvSkeleton::Point: return "Point";
    case ConvSkeleton::Segment: return "Segment";
    case ConvSkeleton::Arc: return "Arc";
    case ConvSkeleton::Triangle: return "Triangle";
    case ConvSkeleton::Plane: return "Plane";
  }
  return "?";
}

double convKernelValue(ConvKernel k, double q) { return kernelAt(k, q); }

std::shared_ptr<const Convolution> Convolution::make(ConvKernel kernel, ConvSkeleton skeleton,
                                                     std::vector<ConvElement> elements) {
  static const size_t sizes[] = {3, 6, 11, 9, 6};
  const size_t need = sizes[static_cast<int>(skeleton)];
  if (skeleton == ConvSkeleton::Plane && (kernel == ConvKernel::Inverse || kernel == ConvKernel::InverseSquare))
    throw std::invalid_argument(std::string("the ") + convKernelName(kernel) +
                                " kernel's integral over a plane diverges");
  std::shared_ptr<Convolution> c(new Convolution());
  c->kernel_ = kernel;
  c->skeleton_ = skeleton;
  uint64_t h = 0x51ed270b27a3c5e1ULL ^ (uint64_t(kernel) << 8) ^ uint64_t(skeleton);
  for (size_t i = 0; i < elements.size(); ++i) {
    const ConvElement& el = elements[i];
    const std::string which = "element " + std::to_string(i + 1);
    if (el.geometry.size() != need)
      throw std::invalid_argument(which + ": expected " + std::to_string(need) + " numbers");
    for (double x : el.geometry)
      if (!std::isfinite(x)) throw std::invalid_argument(which + ": non-finite geometry");
    if (!(el.S > 0.0) || !std::isfinite(el.S)) throw std::invalid_argument(which + ": width S must be positive");
    const double* g = el.geometry.data();
    std::vector<Piece> pieces;
    switch (skeleton) {
      case ConvSkeleton::Point: pieces.push_back({{g[0], g[1], g[2]}, 0.0, 1.0}); break;
      case ConvSkeleton::Segment: {
        double d[3] = {g[3] - g[0], g[4] - g[1], g[5] - g[2]};
        double L = norm(d);
        if (!(L > 0.0)) throw std::invalid_argument(which + ": the segment has zero length");
        const int n = 8;
        for (int j = 0; j < n; ++j) {
          double t = (j + 0.5) / n;
          pieces.push_back({{g[0] + t * d[0], g[1] + t * d[1], g[2] + t * d[2]}, L / (2 * n) * (1 + 1e-9), L / n});
        }
        break;
      }
      case ConvSkeleton::Arc: {
        const double *u = g + 3, *v = g + 6;
        double r = g[9], theta = g[10];
        if (std::fabs(norm(u) - 1) > 1e-9 || std::fabs(norm(v) - 1) > 1e-9 ||
            std::fabs(u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) > 1e-9)
          throw std::invalid_argument(which + ": the arc's frame is not orthonormal");
        if (!(r > 0.0)) throw std::invalid_argument(which + ": the arc's radius must be positive");
        if (!(theta > 0.0) || theta > 2 * kPi * (1 + 1e-12))
          throw std::invalid_argument(which + ": the arc's opening must be in (0, 360] degrees");
        const int n = 8;
        double dt = theta / n;
        for (int j = 0; j < n; ++j) {
          double t = (j + 0.5) * dt, ct = std::cos(t), st = std::sin(t);
          // The sub-arc lies within its half chord's reach of its middle point: 2 r sin(dt/4).
          pieces.push_back({{g[0] + r * (ct * u[0] + st * v[0]), g[1] + r * (ct * u[1] + st * v[1]),
                             g[2] + r * (ct * u[2] + st * v[2])},
                            2 * r * std::sin(dt / 4) * (1 + 1e-9) + 1e-15 * r,
                            r * dt});
        }
        break;
      }
      case ConvSkeleton::Triangle: {
        double e1[3] = {g[3] - g[0], g[4] - g[1], g[5] - g[2]}, e2[3] = {g[6] - g[0], g[7] - g[1], g[8] - g[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double area = 0.5 * norm(n);
        if (!(area > 0.0)) throw std::invalid_argument(which + ": the triangle is degenerate");
        // 16 sub-triangles in barycentric steps of 1/4.
        const int m = 4;
        auto at = [&](double s, double t, double* out) {
          for (int k = 0; k < 3; ++k) out[k] = g[k] + s * e1[k] + t * e2[k];
        };
        for (int a = 0; a < m; ++a)
          for (int b = 0; a + b < m; ++b)
            for (int up = 0; up < 2; ++up) {
              if (up && a + b == m - 1) continue;
              double c[3][3];
              if (!up) {
                at(double(a) / m, double(b) / m, c[0]);
                at(double(a + 1) / m, double(b) / m, c[1]);
                at(double(a) / m, double(b + 1) / m, c[2]);
              } else {
                at(double(a + 1) / m, double(b) / m, c[0]);
                at(double(a + 1) / m, double(b + 1) / m, c[1]);
                at(double(a) / m, double(b + 1) / m, c[2]);
              }
              Piece pc;
              for (int k = 0; k < 3; ++k) pc.c[k] = (c[0][k] + c[1][k] + c[2][k]) / 3.0;
              double rad = 0.0;
              for (auto& cc : c) {
                double dd[3] = {cc[0] - pc.c[0], cc[1] - pc.c[1], cc[2] - pc.c[2]};
                rad = std::max(rad, norm(dd));
              }
              pc.radius = rad * (1 + 1e-9) + 1e-15 * std::sqrt(area);
              pc.measure = area / (m * m);
              pieces.push_back(pc);
            }
        break;
      }
      case ConvSkeleton::Plane:
        if (!(norm(g + 3) > 0.0)) throw std::invalid_argument(which + ": the plane's normal is zero");
        break;
    }
    for (double x : el.geometry) h = mixBits(h, x);
    h = mixBits(h, el.S);
    for (const Piece& pc : pieces) c->largestPiece_ = std::max(c->largestPiece_, pc.radius);
    c->pieces_.push_back(std::move(pieces));
  }
  c->elements_ = std::move(elements);
  c->hash_ = h;
  return c;
}

std::string Convolution::describe() const {
  return std::string("convolution(") + convKernelName(kernel_) + " kernel, " + std::to_string(elements_.size()) +
         " " + convSkeletonName(skeleton_) + (elements_.size() == 1 ? "" : "s") + ")";
}

bool Convolution::sameContent(const FieldFunction& other) const {
  auto* o = dynamic_cast<const Convolution*>(&other);
  if (!o || o->kernel_ != kernel_ || o->skeleton_ != skeleton_ || o->elements_.size() != elements_.size())
    return false;
  for (size_t i = 0; i < elements_.size(); ++i)
    if (o->elements_[i].geometry != elements_[i].geometry || o->elements_[i].S != elements_[i].S) return false;
  return true;
}

void Convolution::elementBound(size_t i, const double lo[3], const double hi[3], double& outLo,
                               double& outHi) const {
  const ConvElement& el = elements_[i];
  if (skeleton_ == ConvSkeleton::Plane) {
    const double* g = el.geometry.data();
    double nl = norm(g + 3), hl = 0.0, hh = 0.0;
    for (int k = 0; k < 3; ++k) {
      double a = planeTerm(g, nl, k, lo[k]), b = planeTerm(g, nl, k, hi[k]);
      hl += std::min(a, b);
      hh += std::max(a, b);
    }
    double amin = hl > 0.0 ? hl : hh < 0.0 ? -hh : 0.0, amax = std::max(std::fabs(hl), std::fabs(hh));
    outLo = planeOf<double>(kernel_, el.S, amax);
    outHi = planeOf<double>(kernel_, el.S, amin);
    return;
  }
  outLo = 0.0;
  outHi = 0.0;
  for (const Piece& pc : pieces_[i]) {
    double near2 = 0.0, far2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      double below = lo[k] - pc.c[k], above = pc.c[k] - hi[k];
      double dn = std::max(std::max(below, above), 0.0);
      double df = std::max(std::fabs(pc.c[k] - lo[k]), std::fabs(pc.c[k] - hi[k]));
      near2 += dn * dn;
      far2 += df * df;
    }
    double dmin = std::max(std::sqrt(near2) - pc.radius, 0.0), dmax = std::sqrt(far2) + pc.radius;
    outLo += pc.measure * kernelAt(kernel_, el.S * dmax);
    outHi += pc.measure * kernelAt(kernel_, el.S * dmin);
  }
}

double Convolution::value(const double p[3]) const {
  double sum = 0.0;
  for (size_t i = 0; i < elements_.size(); ++i) {
    double v = rawElementValue(i, p);
    if (skeleton_ != ConvSkeleton::Plane) {  // clamp into the element's bound at p (rounding noise)
      double lo, hi;
      elementBound(i, p, p, lo, hi);
      if (std::isnan(v)) v = hi;
      v = std::min(std::max(v, lo), hi);
    }
    sum += v;
  }
  return sum;
}


namespace {
// sup over q >= qmin of |h'(q)|: the kernel's steepest slope beyond qmin (eq. 1-6 differentiated;
// the polynomial kernels' maxima rounded up: Gauss sqrt(2/e) at 1/sqrt(2), Metaball 2 at 1/3,
// Soft 1.5834 at q^2 = 0.2535, Quartic 8/(3 sqrt 3) at 1/sqrt(3)); the singular kernels' slopes
// fall with q.
// Past its maximum each slope falls (to 0 at the compact kernels' support, q = 1), so beyond the
// maximum's q the slope at qmin itself is the bound (with a rounding margin).
double maxSlope(ConvKernel k, double qmin) {
  constexpr double up = 1.0 + 1e-12;
  switch (k) {
    case ConvKernel::Gauss: return qmin <= 0.7072 ? 0.8578 : up * 2.0 * qmin * std::exp(-qmin * qmin);
    case ConvKernel::Inverse: return qmin > 0.0 ? 1.0 / (qmin * qmin) : kInf;
    case ConvKernel::InverseSquare: return qmin > 0.0 ? 2.0 / (qmin * qmin * qmin) : kInf;
    case ConvKernel::Metaball: return qmin <= 1.0 / 3.0 ? 2.0 : qmin < 1.0 ? up * 3.0 * (1.0 - qmin) : 0.0;
    case ConvKernel::Soft:
      return qmin <= 0.5035 ? 1.5835
             : qmin < 1.0   ? up * 2.0 * qmin * (1.0 - qmin * qmin) * (22.0 - 12.0 * qmin * qmin) / 9.0
                            : 0.0;
    case ConvKernel::Quartic: return qmin <= 0.5774 ? 1.5397 : qmin < 1.0 ? up * 4.0 * qmin * (1.0 - qmin * qmin) : 0.0;
  }
  return kInf;
}
}  // namespace

Interval Convolution::bound(const Interval box[3]) const {
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    if (std::isnan(box[k].lo) || std::isnan(box[k].hi)) return Interval::everything();
    lo[k] = box[k].lo;
    hi[k] = box[k].hi;
  }
  double sl = 0.0, sh = 0.0;
  for (size_t i = 0; i < elements_.size(); ++i) {
    double l, h;
    elementBound(i, lo, hi, l, h);
    sl += l;
    sh += h;
  }
  // The pieces' bound stops shrinking once the box is smaller than a piece (a ray caster would
  // see a fat surface): there, the value at the box's centre +- the field's slope bound over the
  // box times its half-diagonal r, with a margin for the value's own error (the quadratures'
  // 1e-13 relative, taken as 1e-10 of the field's magnitude bound sh). |grad f| <= sum over
  // pieces of measure * S * sup |h'| beyond the piece's nearest distance.
  double r2 = 0.0, c[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = 0.5 * (lo[k] + hi[k]);
    r2 += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
  }
  const double r = std::sqrt(r2);
  // Not for triangles: their value is a fan of adaptive quadratures, too dear to pay per box.
  if ((skeleton_ == ConvSkeleton::Segment || skeleton_ == ConvSkeleton::Arc) && r < largestPiece_ &&
      std::isfinite(sh)) {
    double slope = 0.0;
    for (size_t i = 0; i < elements_.size(); ++i)
      for (const Piece& pc : pieces_[i]) {
        double near2 = 0.0;
        for (int k = 0; k < 3; ++k) {
          const double dn = std::max(std::max(lo[k] - pc.c[k], pc.c[k] - hi[k]), 0.0);
          near2 += dn * dn;
        }
        const double dmin = std::max(std::sqrt(near2) - pc.radius, 0.0);
        slope += pc.measure * elements_[i].S * maxSlope(kernel_, elements_[i].S * dmin);
      }
    if (std::isfinite(slope)) {
      const double v = value(c), reach = slope * r * (1.0 + 1e-12) + 1e-10 * sh + 1e-300;
      sl = std::max(sl, v - reach);
      sh = std::min(sh, v + reach);
    }
  }
  return Interval(std::nextafter(sl, -kInf), std::nextafter(sh, kInf));
}

}  // namespace frep
