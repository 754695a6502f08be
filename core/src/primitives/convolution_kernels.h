// Internal to the convolution primitive (convolution.cpp, convolution_skeletons.cpp): forward-mode
// dual numbers, Gauss-Legendre quadrature and the kernels (eq. 1-6), as templates over double
// and Dual. One namespace, as when they were one file: unqualified calls inside resolve to these
// overloads (sqrt, exp, ... of a Dual), never to frep's Expr functions of the same names.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "frep/primitives/convolution.h"

namespace frep {
namespace conv_detail {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- forward-mode dual numbers: a value and its three partial derivatives -------------------
struct Dual {
  double v = 0.0;
  double d[3] = {0.0, 0.0, 0.0};
  Dual() = default;
  Dual(double x) : v(x) {}  // NOLINT: constants
};
inline double val(double x) { return x; }
inline double val(const Dual& x) { return x.v; }
inline Dual chain(const Dual& a, double value, double slope) {
  Dual r(value);
  for (int k = 0; k < 3; ++k) r.d[k] = slope * a.d[k];
  return r;
}
inline Dual operator+(const Dual& a, const Dual& b) {
  Dual r(a.v + b.v);
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
inline Dual operator-(const Dual& a, const Dual& b) {
  Dual r(a.v - b.v);
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
inline Dual operator-(const Dual& a) { return chain(a, -a.v, -1.0); }
inline Dual operator*(const Dual& a, const Dual& b) {
  Dual r(a.v * b.v);
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
inline Dual operator/(const Dual& a, const Dual& b) {
  Dual r(a.v / b.v);
  for (int k = 0; k < 3; ++k) r.d[k] = (a.d[k] - r.v * b.d[k]) / b.v;
  return r;
}
inline Dual& operator+=(Dual& a, const Dual& b) { return a = a + b; }
inline Dual sqrt(const Dual& a) {
  double s = std::sqrt(a.v);
  return chain(a, s, s > 0.0 ? 0.5 / s : 0.0);
}
inline Dual exp(const Dual& a) {
  double e = std::exp(a.v);
  return chain(a, e, e);
}
inline Dual expm1(const Dual& a) { return chain(a, std::expm1(a.v), std::exp(a.v)); }
inline Dual log(const Dual& a) { return chain(a, std::log(a.v), 1.0 / a.v); }
inline Dual erf(const Dual& a) { return chain(a, std::erf(a.v), 2.0 / std::sqrt(kPi) * std::exp(-a.v * a.v)); }
inline Dual erfc(const Dual& a) { return chain(a, std::erfc(a.v), -2.0 / std::sqrt(kPi) * std::exp(-a.v * a.v)); }
inline Dual asinh(const Dual& a) { return chain(a, std::asinh(a.v), 1.0 / std::sqrt(1.0 + a.v * a.v)); }
inline Dual atan(const Dual& a) { return chain(a, std::atan(a.v), 1.0 / (1.0 + a.v * a.v)); }
inline Dual cos(const Dual& a) { return chain(a, std::cos(a.v), -std::sin(a.v)); }
inline Dual sin(const Dual& a) { return chain(a, std::sin(a.v), std::cos(a.v)); }
inline Dual atan2(const Dual& y, const Dual& x) {
  Dual r(std::atan2(y.v, x.v));
  double n = x.v * x.v + y.v * y.v;
  for (int k = 0; k < 3; ++k) r.d[k] = n > 0.0 ? (x.v * y.d[k] - y.v * x.d[k]) / n : 0.0;
  return r;
}
using std::asinh;
using std::atan;
using std::atan2;
using std::cos;
using std::erf;
using std::erfc;
using std::exp;
using std::expm1;
using std::log;
using std::sin;
using std::sqrt;
template <typename T>
T vmin(const T& a, const T& b) { return val(b) < val(a) ? b : a; }
template <typename T>
T vmax(const T& a, const T& b) { return val(b) > val(a) ? b : a; }

// ---- Gauss-Legendre rules on [-1, 1] ---------------------------------------------------------
struct Rule {
  std::vector<double> x, w;
};
inline Rule legendre(int n) {
  Rule r;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      double dx = p1 / dp;
      x -= dx;
      if (std::fabs(dx) < 1e-17) break;
    }
    r.x.push_back(x);
    r.w.push_back(2.0 / ((1.0 - x * x) * dp * dp));
  }
  return r;
}
inline const Rule& gl4() {
  static const Rule r = legendre(4);
  return r;
}
inline const Rule& gl10() {
  static const Rule r = legendre(10);
  return r;
}

template <typename T, typename F>
T glPanel(const Rule& rule, const T& a, const T& b, F&& f) {
  T m = (a + b) * 0.5, h = (b - a) * 0.5, s = 0.0;
  for (size_t i = 0; i < rule.x.size(); ++i) s += rule.w[i] * f(m + h * rule.x[i]);
  return s * h;
}

// Adaptive bisection: a panel is accepted when the 10-point rule over it agrees with the sum over
// its halves to 1e-13 relative (or 1e-300 absolute); at most 30 levels and 4000 panel splits per
// integral (then the finest estimates are taken as they are). Decisions look at values only, so
// the dual (gradient) run takes the same panels as the value run.
template <typename T, typename F>
T adaptive(const T& a, const T& b, const T& whole, F& f, int depth, int& budget) {
  T m = (a + b) * 0.5;
  T left = glPanel(gl10(), a, m, f), right = glPanel(gl10(), m, b, f);
  T both = left + right;
  double diff = std::fabs(val(both) - val(whole));
  if (depth >= 30 || --budget <= 0 || diff <= 1e-13 * std::fabs(val(both)) || diff <= 1e-300) return both;
  T l = adaptive(a, m, left, f, depth + 1, budget);
  return l + adaptive(m, b, right, f, depth + 1, budget);
}
// Integral of f over [a, b] split at the given interior points (values; see the header).
template <typename T, typename F>
T integrate(const T& a, const T& b, std::vector<double> splits, F&& f) {
  std::sort(splits.begin(), splits.end());
  T sum = 0.0, lo = a;
  int budget = 4000;
  for (double s : splits) {
    if (!(s > val(lo) && s < val(b))) continue;
    T hi = s;
    sum += adaptive(lo, hi, glPanel(gl10(), lo, hi, f), f, 0, budget);
    lo = hi;
  }
  if (val(b) > val(lo)) sum += adaptive(lo, b, glPanel(gl10(), lo, b, f), f, 0, budget);
  return sum;
}

// ---- kernels (eq. 1-6) -------------------------------------------------------------------------
template <typename T>
T kernelAt(ConvKernel k, const T& q) {
  double qv = val(q);
  switch (k) {
    case ConvKernel::Gauss: return exp(-(q * q));           // eq. 1
    case ConvKernel::Inverse: return 1.0 / q;                // eq. 2
    case ConvKernel::InverseSquare: return 1.0 / (q * q);    // eq. 3
    case ConvKernel::Metaball:                               // eq. 4
      if (qv <= 1.0 / 3.0) return 1.0 - 3.0 * (q * q);
      if (qv <= 1.0) return 1.5 * ((1.0 - q) * (1.0 - q));
      return 0.0;
    case ConvKernel::Soft: {  // eq. 5 (Wyvill's coefficients, see the header)
      if (!(qv < 1.0)) return 0.0;
      T w = 1.0 - q * q;
      return w * w * (9.0 - 4.0 * (q * q)) / 9.0;
    }
    case ConvKernel::Quartic: {  // eq. 6
      if (!(qv < 1.0)) return 0.0;
      T w = 1.0 - q * q;
      return w * w;
    }
  }
  return 0.0;
}
// The same from q^2 (polynomial kernels: no square root; q2 >= 0).
template <typename T>
T kernelSq(ConvKernel k, const T& q2) {
  double v = val(q2);
  switch (k) {
    case ConvKernel::Metaball:
      if (v <= 1.0 / 9.0) return 1.0 - 3.0 * q2;
      return kernelAt(k, sqrt(q2));
    case ConvKernel::Soft: {
      if (!(v < 1.0)) return 0.0;
      T w = 1.0 - q2;
      return w * w * (9.0 - 4.0 * q2) / 9.0;
    }
    case ConvKernel::Quartic: {
      if (!(v < 1.0)) return 0.0;
      T w = 1.0 - q2;
      return w * w;
    }
    default: return kernelAt(k, sqrt(q2));
  }
}

// Radial tail: int_q^inf h(s) s ds (finite kernels only), written without cancellation near the
// support's edge; non-increasing in q (each factor is monotone and non-negative).
template <typename T>
T tail(ConvKernel k, const T& q) {
  double qv = val(q);
  switch (k) {
    case ConvKernel::Gauss: return 0.5 * exp(-(q * q));
    case ConvKernel::Quartic: {
      if (!(qv < 1.0)) return 0.0;
      T w = 1.0 - q * q;
      return w * w * w / 6.0;
    }
    case ConvKernel::Soft: {  // (1/2) int_0^w t^2 (5 + 4t) / 9 dt, t = 1 - s^2
      if (!(qv < 1.0)) return 0.0;
      T w = 1.0 - q * q;
      return w * w * w * (5.0 / 3.0 + w) / 18.0;
    }
    case ConvKernel::Metaball: {
      if (!(qv < 1.0)) return 0.0;
      if (qv >= 1.0 / 3.0) {  // 3/2 int_0^z t^2 (1 - t) dt, z = 1 - q
        T z = 1.0 - q;
        return 1.5 * (z * z * z) * (1.0 / 3.0 - z / 4.0);
      }
      // 2/27 (the outer part) + (1/2) (1/9 - q^2) (5/6 - 3/2 q^2)
      return 2.0 / 27.0 + 0.5 * (1.0 / 9.0 - q * q) * (5.0 / 6.0 - 1.5 * (q * q));
    }
    default: return kInf;
  }
}

// Radial integral int_0^rho h(S sqrt(d^2 + t^2)) t dt for the triangle's fans, given d^2, rho^2.
template <typename T>
T radial(ConvKernel k, double S, const T& d2, const T& rho2) {
  double S2 = S * S;
  switch (k) {
    case ConvKernel::Gauss: return -exp(-(S2 * d2)) * expm1(-(S2 * rho2)) / (2.0 * S2);
    case ConvKernel::Inverse: {  // (q_e - q_h) / S^2 = rho^2 / (S (r_e + |d|))
      T re = sqrt(d2 + rho2), dd = sqrt(d2);
      return rho2 / (S * (re + dd));
    }
    case ConvKernel::InverseSquare: {  // log(q_e / q_h) / S^2 (a point on the plane: tiny floor)
      T dd = vmax(d2, T(1e-300));
      return log((dd + rho2) / dd) / (2.0 * S2);
    }
    default: return (tail(k, S * sqrt(d2)) - tail(k, S * sqrt(d2 + rho2))) / S2;
  }
}

// The plane: 2 pi / S^2 * tail(S |h|).
template <typename T>
T planeOf(ConvKernel k, double S, const T& absH) {
  return 2.0 * kPi / (S * S) * tail(k, S * absH);
}

inline double norm(const double* a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

}  // namespace conv_detail
}  // namespace frep
