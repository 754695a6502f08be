// Exact geometry of a box cut by planes (box_clip.h).
#include "measure/box_clip.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace frep::measure_detail {

namespace {

using V3 = std::array<double, 3>;
using V2 = std::array<double, 2>;

// A convex polygon of at most 4 + 2 k vertices (a face cut by k half-spaces, k <= 4).
struct Poly {
  V3 p[12];
  int n = 0;
};

// Face (axis, side) of the box with its vertices counter-clockwise seen from outside.
Poly face(const double h[3], int axis, int side) {
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const double s = side ? 1.0 : -1.0;
  const double ua[4] = {-1, 1, 1, -1}, ub[4] = {-1, -1, 1, 1};
  Poly f;
  f.n = 4;
  for (int i = 0; i < 4; ++i) {
    V3 v{};
    v[size_t(axis)] = s * h[axis];
    v[size_t(a)] = ua[i] * h[a];
    v[size_t(b)] = ub[i] * h[b];
    f.p[i] = v;
  }
  // (a, b, axis) is right-handed, so this order faces +axis; reverse it on the -h side.
  if (!side) std::reverse(f.p, f.p + 4);
  return f;
}

Poly clip(const Poly& in, const HalfSpace& s) {
  Poly out;
  if (in.n == 0) return out;
  for (int i = 0; i < in.n; ++i) {
    const V3& a = in.p[i];
    const V3& b = in.p[(i + 1) % in.n];
    const double la = s.at(a.data()), lb = s.at(b.data());
    if (la >= 0.0) out.p[out.n++] = a;
    if ((la >= 0.0) != (lb >= 0.0)) {
      const double t = la / (la - lb);
      V3 q;
      for (int k = 0; k < 3; ++k) q[size_t(k)] = a[size_t(k)] + t * (b[size_t(k)] - a[size_t(k)]);
      out.p[out.n++] = q;
    }
  }
  return out;
}

void addTet(Moments& m, const V3& p, const V3& a, const V3& b, const V3& c) {
  const double ax = a[0] - p[0], ay = a[1] - p[1], az = a[2] - p[2];
  const double bx = b[0] - p[0], by = b[1] - p[1], bz = b[2] - p[2];
  const double cx = c[0] - p[0], cy = c[1] - p[1], cz = c[2] - p[2];
  const double v = (ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)) / 6.0;
  if (v == 0.0) return;
  const V3* q[4] = {&p, &a, &b, &c};
  double s[3] = {0, 0, 0};
  for (const V3* x : q)
    for (int i = 0; i < 3; ++i) s[i] += (*x)[size_t(i)];
  m.v += v;
  for (int i = 0; i < 3; ++i) m.m1[i] += v * s[i] / 4.0;
  // integral of y_i y_j over a tetrahedron: V / 20 (sum_k v_ki v_kj + s_i s_j).
  const int I[6] = {0, 1, 2, 0, 1, 2}, J[6] = {0, 1, 2, 1, 2, 0};
  for (int k = 0; k < 6; ++k) {
    double sum = s[I[k]] * s[J[k]];
    for (const V3* x : q) sum += (*x)[size_t(I[k])] * (*x)[size_t(J[k])];
    m.m2[k] += v * sum / 20.0;
  }
}

// Range of c + g . y over the box.
void range(const double h[3], const HalfSpace& s, double& lo, double& hi) {
  double r = 0.0;
  for (int i = 0; i < 3; ++i) r += std::fabs(s.g[i]) * h[i];
  lo = s.c - r;
  hi = s.c + r;
}

// Vertices of box ∩ the half-spaces: every vertex lies on a face of the box when the planes
// are parallel or k = 1 (the only uses), so the clipped faces' vertices are all of them.
std::vector<V3> vertices(const double h[3], const HalfSpace* s, int k) {
  std::vector<V3> out;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Poly f = face(h, axis, side);
      for (int j = 0; j < k; ++j) f = clip(f, s[j]);
      out.insert(out.end(), f.p, f.p + f.n);
    }
  return out;
}

// Orthonormal e1, e2 with n.
void basis(const double n[3], V3& e1, V3& e2) {
  const int m = std::fabs(n[0]) <= std::fabs(n[1]) && std::fabs(n[0]) <= std::fabs(n[2]) ? 0
                : std::fabs(n[1]) <= std::fabs(n[2])                                      ? 1
                                                                                          : 2;
  V3 a{0, 0, 0};
  a[size_t(m)] = 1.0;
  // e1 = a x n, normalised; e2 = n x e1.
  e1 = {a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0]};
  const double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (double& x : e1) x /= l;
  e2 = {n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]};
}

double cross2(const V2& o, const V2& a, const V2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Convex hull, counter-clockwise (Andrew's monotone chain).
std::vector<V2> hull(std::vector<V2> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return {};
  std::vector<V2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross2(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

double area2(const std::vector<V2>& p) {
  double a = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const V2& u = p[i];
    const V2& w = p[(i + 1) % p.size()];
    a += u[0] * w[1] - u[1] * w[0];
  }
  return 0.5 * std::fabs(a);
}

std::vector<V2> projectHull(const double h[3], const HalfSpace* s, int k, const double n[3]) {
  V3 e1, e2;
  basis(n, e1, e2);
  std::vector<V2> p;
  for (const V3& v : vertices(h, s, k))
    p.push_back({v[0] * e1[0] + v[1] * e1[1] + v[2] * e1[2], v[0] * e2[0] + v[1] * e2[1] + v[2] * e2[2]});
  return hull(std::move(p));
}

// Convex polygon p clipped by the convex counter-clockwise polygon q (Sutherland-Hodgman).
std::vector<V2> clip2(std::vector<V2> p, const std::vector<V2>& q) {
  for (size_t e = 0; e < q.size() && !p.empty(); ++e) {
    const V2& a = q[e];
    const V2& b = q[(e + 1) % q.size()];
    std::vector<V2> out;
    for (size_t i = 0; i < p.size(); ++i) {
      const V2& u = p[i];
      const V2& w = p[(i + 1) % p.size()];
      const double du = cross2(a, b, u), dw = cross2(a, b, w);
      if (du >= 0) out.push_back(u);
      if ((du >= 0) != (dw >= 0)) {
        const double t = du / (du - dw);
        out.push_back({u[0] + t * (w[0] - u[0]), u[1] + t * (w[1] - u[1])});
      }
    }
    p = std::move(out);
  }
  return p;
}

}  // namespace

Moments boxMoments(const double h[3]) {
  Moments m;
  m.v = 8.0 * h[0] * h[1] * h[2];
  for (int i = 0; i < 3; ++i) m.m2[i] = m.v * h[i] * h[i] / 3.0;
  return m;
}

Moments clippedMoments(const double h[3], const HalfSpace& s) {
  double lo, hi;
  range(h, s, lo, hi);
  if (lo >= 0.0) return boxMoments(h);
  if (hi <= 0.0) return Moments{};
  // A point of the plane (the foot of the perpendicular from the centre): tetrahedra from it
  // over the clipped faces; the cut face, in the plane, adds nothing.
  const double g2 = s.g[0] * s.g[0] + s.g[1] * s.g[1] + s.g[2] * s.g[2];
  const V3 p{-s.c * s.g[0] / g2, -s.c * s.g[1] / g2, -s.c * s.g[2] / g2};
  Moments m;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const Poly f = clip(face(h, axis, side), s);
      for (int i = 1; i + 1 < f.n; ++i) addTet(m, p, f.p[0], f.p[i], f.p[i + 1]);
    }
  return m;
}

double clippedVolume(const double h[3], const HalfSpace& s) { return clippedMoments(h, s).v; }

double projectedArea(const double h[3], const HalfSpace* s, int k, const double n[3]) {
  return area2(projectHull(h, s, k, n));
}

double projectedOverlap(const double h[3], const HalfSpace& a, const HalfSpace& b, const double n[3]) {
  const std::vector<V2> pa = projectHull(h, &a, 1, n);
  const std::vector<V2> pb = projectHull(h, &b, 1, n);
  if (pa.empty() || pb.empty()) return 0.0;
  const std::vector<V2> c = clip2(pa, pb);
  return c.size() < 3 ? 0.0 : area2(c);
}

double faceArea(const double h[3], int axis, int side, const HalfSpace& s) {
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const double u[2] = {-h[a], h[a]}, v[2] = {-h[b], h[b]};
  return rectArea(h, axis, side, u, v, s);
}

double rectArea(const double h[3], int axis, int side, const double u[2], const double v[2], const HalfSpace& s) {
  Poly r;
  r.n = 4;
  const double ua[4] = {u[0], u[1], u[1], u[0]}, vb[4] = {v[0], v[0], v[1], v[1]};
  for (int i = 0; i < 4; ++i) {
    V3 p{};
    p[size_t(axis)] = side ? h[axis] : -h[axis];
    p[size_t((axis + 1) % 3)] = ua[i];
    p[size_t((axis + 2) % 3)] = vb[i];
    r.p[i] = p;
  }
  const Poly f = clip(r, s);
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  std::vector<V2> p;
  for (int i = 0; i < f.n; ++i) p.push_back({f.p[i][size_t(a)], f.p[i][size_t(b)]});
  return p.size() < 3 ? 0.0 : area2(p);
}

}  // namespace frep::measure_detail
