// Convolution skeletons (Vyatkin-Perturbation eq. 7, 9): the integral of a kernel over a point,
// a segment, an arc, a triangle or a plane, in closed form or by adaptive quadrature, and the
// element values and gradients built on them (frep/primitives/convolution.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "primitives/convolution_kernels.h"

namespace frep {
namespace conv_detail {

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

}  // namespace conv_detail

namespace {
using conv_detail::Dual;
using conv_detail::V3;
using conv_detail::elementField;
}  // namespace

double Convolution::rawElementValue(size_t i, const double p[3]) const {
  return elementField<double>(kernel_, skeleton_, elements_[i], V3<double>{p[0], p[1], p[2]});
}

double Convolution::gradient(const double p[3], double g[3]) const {
  Dual x(p[0]), y(p[1]), z(p[2]);
  x.d[0] = y.d[1] = z.d[2] = 1.0;
  Dual sum = 0.0;
  for (const ConvElement& el : elements_) sum += elementField<Dual>(kernel_, skeleton_, el, V3<Dual>{x, y, z});
  for (int k = 0; k < 3; ++k) g[k] = sum.d[k];
  return value(p);
}

}  // namespace frep
