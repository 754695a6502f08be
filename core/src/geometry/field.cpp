// Geometry fields: default gradient, the Lipschitz interval bound and content identity.
#include "frep/geometry/field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <typeinfo>

namespace frep {

double DistanceField::gradient(const double p[3], double g[3]) const {
  double q[3] = {p[0], p[1], p[2]};
  for (int i = 0; i < 3; ++i) {
    const double h = 1e-6 * std::max(1.0, std::fabs(p[i]));
    q[i] = p[i] + h;
    const double fp = value(q);
    q[i] = p[i] - h;
    const double fm = value(q);
    q[i] = p[i];
    g[i] = (fp - fm) / (2.0 * h);
  }
  return value(p);
}

double DistanceField::gradientFromNearest(double f, const double* p, const double* q, double g[3]) const {
  const double d = std::fabs(f);
  const double s = f > 0.0 ? 1.0 : -1.0;  // inside: f = d grows away from the boundary
  for (int k = 0; k < 3; ++k) g[k] = k < dims() && d != 0.0 ? s * (p[k] - q[k]) / d : 0.0;
  return f;
}

Interval DistanceField::bound(const Interval box[3]) const {
  double c[3] = {0.0, 0.0, 0.0}, r2 = 0.0;
  for (int i = 0; i < dims(); ++i) {
    if (!std::isfinite(box[i].lo) || !std::isfinite(box[i].hi)) return Interval::everything();
    c[i] = 0.5 * (box[i].lo + box[i].hi);
    const double h = std::max(box[i].hi - c[i], c[i] - box[i].lo);
    r2 += h * h;
  }
  // A planar field reads p[2] nowhere: its value at any z is the value at z = 0.
  const double v = value(c);
  if (std::isnan(v)) return Interval::everything();
  // |f(p) - f(c)| <= L |p - c| <= L r; the outward slack covers the rounding of the centre, of
  // the radius and of the value itself.
  const double r = lipschitz() * std::sqrt(r2) * (1.0 + 1e-12);
  const double slack = 1e-12 * (std::fabs(v) + r) + std::numeric_limits<double>::denorm_min();
  return {v - r - slack, v + r + slack};
}

bool DistanceField::sameContent(const FieldFunction& other) const {
  if (typeid(other) != typeid(*this) || other.contentHash() != contentHash()) return false;
  return sameGeometry(static_cast<const DistanceField&>(other));
}

}  // namespace frep
