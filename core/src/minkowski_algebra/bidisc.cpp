// The closed-form bidisc gauge and the bicircle quartic (bidisc.h).
#include "frep/minkowski_algebra/bidisc.h"

#include <cmath>

namespace frep::minkowski {
namespace {

// The same formula for doubles and expressions.
double select(double c, double a, double b) { return c != 0 ? a : b; }
double le(double a, double b) { return a <= b ? 1.0 : 0.0; }
double ge(double a, double b) { return a >= b ? 1.0 : 0.0; }
double eq(double a, double b) { return a == b ? 1.0 : 0.0; }

template <class T>
T gauge(const T& u, const T& w, const T& h, double a, double b) {
  using std::abs;
  using std::max;
  using std::min;
  using std::sqrt;
  const T zero(0.0);
  auto root = [&](const T& v) { return sqrt(max(v, zero)); };
  // The two terms at the ends t = 0 and t = h of the interval where the max lies.
  const T g1at0 = T(a) - w, g2at0 = T(b) - sqrt(u * u + h * h);
  const T g1atH = T(a) - sqrt(w * w + h * h), g2atH = T(b) - u;
  // The crossing value v: √((a − v)² − w²) + √((b − v)² − u²) = h, squared twice:
  // (h² − δ²) v² + (kδ − 2h²b) v + h²(b² − u²) − k²/4 = 0, δ = b − a, k = h² − u² + w² + δ(a + b).
  const double d = b - a;
  const T h2 = h * h;
  const T k = h2 - u * u + w * w + T(d * (a + b));
  const T qa = h2 - T(d * d), qb = k * T(d) - h2 * T(2 * b), qc = h2 * (T(b * b) - u * u) - k * k * T(0.25);
  const T disc = root(qb * qb - T(4.0) * qa * qc);
  T q = T(-0.5) * (qb + select(ge(qb, zero), disc, -disc));
  q = select(eq(q, zero), T(1e-300), q);
  const T r1 = q / select(eq(qa, zero), T(1e-300), qa), r2 = qc / q;
  // The root of the unsquared equation inside [lo, hi] (the crossing lies between the ends).
  const T lo = max(g1atH, g2at0), hi = min(g1at0, g2atH);
  auto miss = [&](const T& v) {
    const T res = root((T(a) - v) * (T(a) - v) - w * w) + root((T(b) - v) * (T(b) - v) - u * u) - h;
    return abs(res) + max(lo - v, zero) + max(v - hi, zero);
  };
  const T cross = min(max(select(le(miss(r1), miss(r2)), r1, r2), lo), hi);
  return select(le(g1at0, g2at0), g1at0, select(ge(g1atH, g2atH), g2atH, cross));
}

}  // namespace

double bidiscGauge(double u, double w, double h, double a, double b) { return gauge(u, w, h, a, b); }
Expr bidiscGauge(const Expr& u, const Expr& w, const Expr& h, double a, double b) {
  return gauge(u, w, h, a, b);
}

double bicirclePolynomial(double x, double y, double z, double a, double b) {
  const double q = x * x - y * y + z * z + a * a - b * b;
  return q * q - 4 * z * z * (a * a - y * y);
}

std::vector<QuarticTerm> bicircleTerms(double a, double b) {
  // Expanded: x⁴ + y⁴ + z⁴ − 2x²y² + 2x²z² + 2y²z² + 2c x² − 2c y² + (2c − 4a²) z² + c²,
  // c = a² − b².
  const double c = a * a - b * b;
  return {{4, 0, 0, 1},     {0, 4, 0, 1},      {0, 0, 4, 1},  {2, 2, 0, -2},
          {2, 0, 2, 2},     {0, 2, 2, 2},      {2, 0, 0, 2 * c}, {0, 2, 0, -2 * c},
          {0, 0, 2, 2 * c - 4 * a * a}, {0, 0, 0, c * c}};
}

}  // namespace frep::minkowski
