// Exact predicates on quantised triangle meshes: whether two triangles of a mesh meet anywhere
// but in a shared vertex or a shared edge (without folding). Used by the mesh simplifier before
// every change and by the tests' self-intersection check, so both judge alike.
//
// Coordinates are integers (a mesh's positions quantised to a fixed lattice, at most 2^40 steps
// across), every orientation is an exact integer determinant in 128 bits.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace frep {
namespace exact {


using P = std::array<int64_t, 3>;

inline int sgn(__int128 v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

// Sign of the orientation determinant. A floating-point filter first: the differences are exact
// in double (< 2^53), and Shewchuk's forward error bound for the products and sums
// ((7 + 56 eps) eps times the permanent; "Adaptive Precision Floating-Point Arithmetic", 1997)
// decides nearly every case; the rest in exact 128-bit integers.
inline int orient3d(const P& a, const P& b, const P& c, const P& d) {
  {
    double u[3], v[3], w[3];
    for (int i = 0; i < 3; ++i) {
      u[i] = double(b[i] - a[i]);
      v[i] = double(c[i] - a[i]);
      w[i] = double(d[i] - a[i]);
    }
    const double m0 = v[1] * w[2] - v[2] * w[1], m1 = v[0] * w[2] - v[2] * w[0], m2 = v[0] * w[1] - v[1] * w[0];
    const double det = u[0] * m0 - u[1] * m1 + u[2] * m2;
    const double perm = std::abs(u[0]) * (std::abs(v[1] * w[2]) + std::abs(v[2] * w[1])) +
                        std::abs(u[1]) * (std::abs(v[0] * w[2]) + std::abs(v[2] * w[0])) +
                        std::abs(u[2]) * (std::abs(v[0] * w[1]) + std::abs(v[1] * w[0]));
    const double bound = 7.7715611723761027e-16 * perm;
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  __int128 u[3], v[3], w[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = b[i] - a[i];
    v[i] = c[i] - a[i];
    w[i] = d[i] - a[i];
  }
  return sgn(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]));
}

// Drop the axis along which the plane of (a, b, c) has the largest normal component.
inline int dropAxis(const P& a, const P& b, const P& c) {
  __int128 n[3];
  __int128 u[3], v[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = b[i] - a[i];
    v[i] = c[i] - a[i];
  }
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  for (auto& x : n) x = x < 0 ? -x : x;
  return n[0] >= n[1] && n[0] >= n[2] ? 0 : (n[1] >= n[2] ? 1 : 2);
}

inline int orient2d(int drop, const P& a, const P& b, const P& c) {
  int i = drop == 0 ? 1 : 0, j = drop == 2 ? 1 : 2;
  __int128 r = __int128(b[i] - a[i]) * (c[j] - a[j]) - __int128(b[j] - a[j]) * (c[i] - a[i]);
  return sgn(r);
}

inline bool onSegment2d(int drop, const P& p, const P& q, const P& x) {  // x collinear with pq
  for (int k = 0; k < 3; ++k) {
    if (k == drop) continue;
    if (x[k] < std::min(p[k], q[k]) || x[k] > std::max(p[k], q[k])) return false;
  }
  return true;
}

inline bool segSeg2d(int drop, const P& p, const P& q, const P& a, const P& b) {
  int o1 = orient2d(drop, p, q, a), o2 = orient2d(drop, p, q, b), o3 = orient2d(drop, a, b, p), o4 = orient2d(drop, a, b, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  if (o1 == 0 && onSegment2d(drop, p, q, a)) return true;
  if (o2 == 0 && onSegment2d(drop, p, q, b)) return true;
  if (o3 == 0 && onSegment2d(drop, a, b, p)) return true;
  if (o4 == 0 && onSegment2d(drop, a, b, q)) return true;
  return false;
}

inline bool inTri2d(int drop, const P& x, const P& a, const P& b, const P& c) {
  int o1 = orient2d(drop, a, b, x), o2 = orient2d(drop, b, c, x), o3 = orient2d(drop, c, a, x);
  return !((o1 < 0 || o2 < 0 || o3 < 0) && (o1 > 0 || o2 > 0 || o3 > 0));
}

// Closed segment pq against closed triangle abc.
inline bool segTri(const P& p, const P& q, const P& a, const P& b, const P& c) {
  int op = orient3d(a, b, c, p), oq = orient3d(a, b, c, q);
  if (op * oq > 0) return false;
  if (op == 0 && oq == 0) {
    int d = dropAxis(a, b, c);
    return inTri2d(d, p, a, b, c) || inTri2d(d, q, a, b, c) || segSeg2d(d, p, q, a, b) || segSeg2d(d, p, q, b, c) ||
           segSeg2d(d, p, q, c, a);
  }
  int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  return !((s1 < 0 || s2 < 0 || s3 < 0) && (s1 > 0 || s2 > 0 || s3 > 0));
}

inline bool triTri(const std::array<P, 3>& t, const std::array<P, 3>& u) {
  for (int k = 0; k < 3; ++k)  // disjoint boxes
    if (std::max({t[0][k], t[1][k], t[2][k]}) < std::min({u[0][k], u[1][k], u[2][k]}) ||
        std::max({u[0][k], u[1][k], u[2][k]}) < std::min({t[0][k], t[1][k], t[2][k]}))
      return false;
  // One triangle strictly on one side of the other's plane.
  int a = orient3d(t[0], t[1], t[2], u[0]), b = orient3d(t[0], t[1], t[2], u[1]), c = orient3d(t[0], t[1], t[2], u[2]);
  if ((a > 0 && b > 0 && c > 0) || (a < 0 && b < 0 && c < 0)) return false;
  a = orient3d(u[0], u[1], u[2], t[0]), b = orient3d(u[0], u[1], u[2], t[1]), c = orient3d(u[0], u[1], u[2], t[2]);
  if ((a > 0 && b > 0 && c > 0) || (a < 0 && b < 0 && c < 0)) return false;
  for (int i = 0; i < 3; ++i) {
    if (segTri(t[i], t[(i + 1) % 3], u[0], u[1], u[2])) return true;
    if (segTri(u[i], u[(i + 1) % 3], t[0], t[1], t[2])) return true;
  }
  return false;
}

// Segment from v towards a (v excluded) meets triangle (v, c, d)?
inline bool rayIntoCorner(const P& v, const P& a, const P& c, const P& d) {
  if (orient3d(v, c, d, a) != 0) return false;  // leaves the plane at once
  int drop = dropAxis(v, c, d);
  int s = orient2d(drop, v, c, d);
  if (s == 0) return true;  // degenerate corner: report
  return orient2d(drop, v, c, a) * s >= 0 && orient2d(drop, v, a, d) * s >= 0;
}

}  // namespace exact

// Triangles t and u (vertex indices) with quantised corners T and U: true when they meet
// improperly: no shared vertex and any contact; one shared vertex and contact beyond it; a
// shared edge and the two folded onto each other in one plane; or the same triangle twice.
inline bool improperPair(const std::array<uint32_t, 3>& t, const std::array<exact::P, 3>& T,
                         const std::array<uint32_t, 3>& u, const std::array<exact::P, 3>& U) {
  int shared = 0, ti = -1, ui = -1;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (t[a] == u[b]) ++shared, ti = a, ui = b;
  if (shared == 0) return exact::triTri(T, U);
  if (shared == 1) {
    const exact::P& v = T[ti];
    const exact::P &a = T[(ti + 1) % 3], &b = T[(ti + 2) % 3], &c = U[(ui + 1) % 3], &d = U[(ui + 2) % 3];
    // One triangle off the other's plane except at v: they meet in v alone (the common case).
    int oc = exact::orient3d(T[0], T[1], T[2], c), od = exact::orient3d(T[0], T[1], T[2], d);
    if (oc * od > 0) return false;
    int oa = exact::orient3d(U[0], U[1], U[2], a), ob = exact::orient3d(U[0], U[1], U[2], b);
    if (oa * ob > 0) return false;
    return exact::segTri(a, b, U[0], U[1], U[2]) || exact::segTri(c, d, T[0], T[1], T[2]) ||
           exact::rayIntoCorner(v, a, c, d) || exact::rayIntoCorner(v, b, c, d) || exact::rayIntoCorner(v, c, a, b) ||
           exact::rayIntoCorner(v, d, a, b);
  }
  if (shared == 2) {
    // The vertices not shared; folded when coplanar and on the same side of the edge.
    int ta = 0, ub = 0;
    for (int a = 0; a < 3; ++a) {
      if (t[a] != u[0] && t[a] != u[1] && t[a] != u[2]) ta = a;
      if (u[a] != t[0] && u[a] != t[1] && u[a] != t[2]) ub = a;
    }
    const exact::P &e0 = T[(ta + 1) % 3], &e1 = T[(ta + 2) % 3];
    if (exact::orient3d(e0, e1, T[ta], U[ub]) != 0) return false;
    int drop = exact::dropAxis(e0, e1, T[ta]);
    return exact::orient2d(drop, e0, e1, T[ta]) * exact::orient2d(drop, e0, e1, U[ub]) > 0;
  }
  return true;  // the same triangle twice
}

}  // namespace frep
