// Convolution kernels x skeletons (Vyatkin-Perturbation eq. 1-7, 9): values, gradients, bounds.
// The methods and their accuracy are described in frep/primitives/convolution.h.
#include "frep/primitives/convolution.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace frep {

namespace {

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
Rule legendre(int n) {
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
const Rule& gl4() {
  static const Rule r = legendre(4);
  return r;
}
const Rule& gl10() {
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

// ---- skeleton integrals ----------------------------------------------------------------------
template <typename T>
struct V3 {
  T x, y, z;
};
template <typename T>
T dot(const V3<T>& a, const double* b) { return a.x * b[0] + a.y * b[1] + a.z * b[2]; }

template <typename T>
T pointField(ConvKernel k, double S, const double* c, const V3<T>& p) {
  T dx = p.x - c[0], dy = p.y - c[1], dz = p.z - c[2];
  T r2 = dx * dx + dy * dy + dz * dz;
  return kernelAt(k, S * sqrt(r2));
}

// Antiderivative of 3/2 (1 - S sqrt(d^2 + u^2))^2 in u (outer metaball piece).
template <typename T>
T metaOuterPrimitive(double S, const T& d2, const T& u) {
  T r = sqrt(d2 + u * u);
  T psi = u * r;
  if (val(d2) > 0.0) psi += d2 * asinh(u / sqrt(d2));
  return 1.5 * (u + (S * S) * (d2 * u + u * u * u / 3.0)) - 1.5 * S * psi;
}

// The segment b -> e: u along it from the foot of the perpendicular, on [a1, a2].
template <typename T>
T segmentField(ConvKernel k, double S, const double* g, const V3<T>& p) {
  double dir[3] = {g[3] - g[0], g[4] - g[1], g[5] - g[2]};
  double L = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (double& c : dir) c /= L;
  V3<T> w = {p.x - g[0], p.y - g[1], p.z - g[2]};
  T t0 = dot(w, dir);
  T px = w.x - t0 * dir[0], py = w.y - t0 * dir[1], pz = w.z - t0 * dir[2];
  T d2 = px * px + py * py + pz * pz;
  T a1 = -t0, a2 = L - t0;
  double S2 = S * S;
  switch (k) {
    case ConvKernel::Gauss: {  // sqrt(pi)/(2S) exp(-S^2 d^2) [erf(S u)]
      T diff;
      if (val(a1) >= 0.0) diff = erfc(S * a1) - erfc(S * a2);
      else if (val(a2) <= 0.0) diff = erfc(-S * a2) - erfc(-S * a1);
      else diff = erf(S * a2) - erf(S * a1);
      return std::sqrt(kPi) / (2.0 * S) * exp(-(S2 * d2)) * diff;
    }
    case ConvKernel::Inverse: {  // (1/S) [asinh(u / d)], in log form on one side
      T r1 = sqrt(d2 + a1 * a1), r2 = sqrt(d2 + a2 * a2);
      if (val(a1) >= 0.0) return log((a2 + r2) / (a1 + r1)) / S;
      if (val(a2) <= 0.0) return log((r1 - a1) / (r2 - a2)) / S;
      T d = sqrt(d2);
      if (val(d) == 0.0) return kInf;
      return (asinh(a2 / d) + asinh(-a1 / d)) / S;
    }
    case ConvKernel::InverseSquare: {  // (1/(S^2 d)) (atan(a2/d) - atan(a1/d))
      T d = sqrt(d2);
      if (val(d) == 0.0) {
        if (val(a1) > 0.0 || val(a2) < 0.0) return (1.0 / a1 - 1.0 / a2) / S2;
        return kInf;
      }
      return atan2(d * (a2 - a1), d2 + a1 * a2) / (S2 * d);
    }
    default: break;
  }
  // Polynomial kernels: clip to the support u^2 < 1/S^2 - d^2.
  T m2 = 1.0 / S2 - d2;
  if (!(val(m2) > 0.0)) return 0.0;
  T m = sqrt(m2);
  T lo = vmax(a1, -m), hi = vmin(a2, m);
  if (!(val(hi) > val(lo))) return 0.0;
  auto poly = [&](const T& u) { return kernelSq(k, S2 * (d2 + u * u)); };
  if (k != ConvKernel::Metaball) return glPanel(gl4(), lo, hi, poly);
  // Metaball: inner piece |u| < mi (polynomial), outer pieces by the antiderivative.
  T mi2 = 1.0 / (9.0 * S2) - d2;
  if (!(val(mi2) > 0.0))
    return metaOuterPrimitive(S, d2, hi) - metaOuterPrimitive(S, d2, lo);
  T mi = sqrt(mi2);
  T sum = 0.0;
  T ilo = vmax(lo, -mi), ihi = vmin(hi, mi);
  auto inner = [&](const T& u) { return 1.0 - 3.0 * (S2 * (d2 + u * u)); };
  if (val(ihi) > val(ilo)) sum += glPanel(gl4(), ilo, ihi, inner);
  if (val(lo) < -val(mi)) {
    T e = vmin(hi, -mi);
    sum += metaOuterPrimitive(S, d2, e) - metaOuterPrimitive(S, d2, lo);
  }
  if (val(hi) > val(mi)) {
    T s = vmax(lo, mi);
    sum += metaOuterPrimitive(S, d2, hi) - metaOuterPrimitive(S, d2, s);
  }
  return sum;
}

bool compact(ConvKernel k) {
  return k == ConvKernel::Metaball || k == ConvKernel::Soft || k == ConvKernel::Quartic;
}

// Squared distances 1/S^2 (support edge) and 1/(9 S^2) (the metaball's joint) where the
// integrands have kinks.
std::vector<double> kinkRadii2(ConvKernel k, double S) {
  std::vector<double> r;
  if (compact(k)) r.push_back(1.0 / (S * S));
  if (k == ConvKernel::Metaball) r.push_back(1.0 / (9.0 * S * S));
  return r;
}

// The arc c + r (cos t u + sin t v), 0 <= t <= theta: r int h(S |X - s(t)|) dt.
template <typename T>
T arcField(ConvKernel k, double S, const double* g, const V3<T>& p) {
  const double *c = g, *u = g + 3, *v = g + 6;
  double r = g[9], theta = g[10];
  V3<T> q = {p.x - c[0], p.y - c[1], p.z - c[2]};
  double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  T qx = dot(q, u), qy = dot(q, v), qz = dot(q, n);
  T qz2 = qz * qz;
  auto f = [&](const T& t) {
    T dx = qx - r * cos(t), dy = qy - r * sin(t);
    return kernelSq(k, (S * S) * (dx * dx + dy * dy + qz2));
  };
  // Splits: the nearest point's angle phi0 and where |X - s|^2 = A - B cos(t - phi0) crosses a kink.
  double qxv = val(qx), qyv = val(qy), qzv = val(qz);
  double rho = std::sqrt(qxv * qxv + qyv * qyv), phi0 = std::atan2(qyv, qxv);
  double A = rho * rho + qzv * qzv + r * r, B = 2.0 * r * rho;
  std::vector<double> angles;
  if (B > 0.0) {
    angles.push_back(0.0);
    for (double k2 : kinkRadii2(k, S)) {
      double c2 = (A - k2) / B;
      if (c2 > -1.0 && c2 < 1.0) {
        double psi = std::acos(c2);
        angles.push_back(psi);
        angles.push_back(-psi);
      }
    }
  }
  std::vector<double> splits;
  for (double a : angles)
    for (int turn = -1; turn <= 2; ++turn) splits.push_back(phi0 + a + 2.0 * kPi * turn);
  return r * integrate(T(0.0), T(theta), splits, f);
}

// The triangle (A, B, C): signed sum over edges of fans from the foot F of the perpendicular.
// For edge P -> Q with unit direction w, the in-plane signed distance a of F from the edge line
// (positive towards the triangle) and t = (P - X).w ... (Q - X).w along it, the fan is
// psi = atan(t / |a|) in [psiP, psiQ] and radius rho(psi) = |a| / cos(psi):
//   fan = int radial(d^2, a^2 / cos^2 psi) d psi,  triangle = sum sign(a) fan.
template <typename T>
T triangleField(ConvKernel k, double S, const double* g, const V3<T>& p) {
  const double* v[3] = {g, g + 3, g + 6};
  double e1[3], e2[3], n[3];
  for (int i = 0; i < 3; ++i) e1[i] = v[1][i] - v[0][i], e2[i] = v[2][i] - v[0][i];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& c : n) c /= nl;
  V3<T> w0 = {p.x - v[0][0], p.y - v[0][1], p.z - v[0][2]};
  T d = dot(w0, n);
  T d2 = d * d;
  if (compact(k) && !(S * std::fabs(val(d)) < 1.0)) return 0.0;
  T sum = 0.0;
  for (int e = 0; e < 3; ++e) {
    const double *P = v[e], *Q = v[(e + 1) % 3];
    double w[3] = {Q[0] - P[0], Q[1] - P[1], Q[2] - P[2]};
    double wl = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (double& c : w) c /= wl;
    double in[3] = {n[1] * w[2] - n[2] * w[1], n[2] * w[0] - n[0] * w[2], n[0] * w[1] - n[1] * w[0]};
    V3<T> xp = {p.x - P[0], p.y - P[1], p.z - P[2]};
    T a = dot(xp, in);
    double av = val(a);
    if (av == 0.0) continue;
    T aa = av > 0.0 ? a : -a;
    T tP = -dot(xp, w), tQ = tP + wl;
    T psiP = atan(tP / aa), psiQ = atan(tQ / aa);
    T a2 = aa * aa;
    auto f = [&](const T& psi) {
      T c = cos(psi);
      return radial(k, S, d2, a2 / (c * c));
    };
    std::vector<double> splits;
    for (double k2 : kinkRadii2(k, S)) {  // rho^2 = k2 - d^2 at |psi| = acos(|a| / rho)
      double rho2 = k2 - val(d2);
      if (rho2 > av * av) {
        double psi = std::acos(std::fabs(av) / std::sqrt(rho2));
        splits.push_back(psi);
        splits.push_back(-psi);
      }
    }
    T fan = integrate(psiP, psiQ, splits, f);
    sum += av > 0.0 ? fan : -fan;
  }
  return sum;
}

// The plane: 2 pi / S^2 * tail(S |h|).
template <typename T>
T planeOf(ConvKernel k, double S, const T& absH) {
  return 2.0 * kPi / (S * S) * tail(k, S * absH);
}

// Signed distance to the plane, term by term in a fixed order (the bound repeats it).
double planeTerm(const double* g, double nl, int i, double x) { return (x - g[i]) * (g[3 + i] / nl); }

uint64_t mixBits(uint64_t h, double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return h ^ (b + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

double norm(const double* a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

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

namespace {
template <typename T>
T elementField(ConvKernel k, ConvSkeleton s, const ConvElement& el, const V3<T>& p) {
  const double* g = el.geometry.data();
  switch (s) {
    case ConvSkeleton::Point: return pointField(k, el.S, g, p);
    case ConvSkeleton::Segment: return segmentField(k, el.S, g, p);
    case ConvSkeleton::Arc: return arcField(k, el.S, g, p);
    case ConvSkeleton::Triangle: return triangleField(k, el.S, g, p);
    case ConvSkeleton::Plane: {
      double nl = norm(g + 3);
      T h = (p.x - g[0]) * (g[3] / nl) + (p.y - g[1]) * (g[4] / nl) + (p.z - g[2]) * (g[5] / nl);
      return planeOf(k, el.S, val(h) < 0.0 ? -h : h);
    }
  }
  return 0.0;
}
}  // namespace

double Convolution::rawElementValue(size_t i, const double p[3]) const {
  return elementField<double>(kernel_, skeleton_, elements_[i], V3<double>{p[0], p[1], p[2]});
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

double Convolution::gradient(const double p[3], double g[3]) const {
  Dual x(p[0]), y(p[1]), z(p[2]);
  x.d[0] = y.d[1] = z.d[2] = 1.0;
  Dual sum = 0.0;
  for (const ConvElement& el : elements_) sum += elementField<Dual>(kernel_, skeleton_, el, V3<Dual>{x, y, z});
  for (int k = 0; k < 3; ++k) g[k] = sum.d[k];
  return value(p);
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
