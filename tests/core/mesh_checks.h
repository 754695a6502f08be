// Reusable checks of indexed triangle meshes (core mesher tests and the frep mesh round trip):
// directed-edge pairing (watertight and consistently oriented), Euler characteristic,
// connected components, enclosed volume and area, smallest triangle area.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace mesh_checks {

using Vec3 = std::array<double, 3>;
using Tri = std::array<uint32_t, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Every directed edge (a, b) of a triangle occurs exactly once and its reverse (b, a) occurs
// too: the surface is closed, 2-manifold at edges and consistently oriented. Returns "" or the
// first problem found.
inline std::string checkEdgePairs(const std::vector<Tri>& tris, size_t numVertices) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t t = 0; t < tris.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      uint32_t a = tris[t][c], b = tris[t][(c + 1) % 3];
      if (a >= numVertices || b >= numVertices) return "triangle " + std::to_string(t) + " has a bad index";
      if (a == b) return "triangle " + std::to_string(t) + " repeats a vertex";
      if (++directed[{a, b}] > 1)
        return "directed edge " + std::to_string(a) + "->" + std::to_string(b) + " occurs twice";
    }
  }
  for (const auto& [e, n] : directed)
    if (!directed.count({e.second, e.first}))
      return "edge " + std::to_string(e.first) + "->" + std::to_string(e.second) + " has no opposite";
  return "";
}

inline long eulerCharacteristic(const std::vector<Tri>& tris, size_t numVertices) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const Tri& t : tris)
    for (int c = 0; c < 3; ++c) edges[{std::min(t[c], t[(c + 1) % 3]), std::max(t[c], t[(c + 1) % 3])}] = 1;
  return long(numVertices) - long(edges.size()) + long(tris.size());
}

// Connected components of the vertices used by triangles.
inline int components(const std::vector<Tri>& tris, size_t numVertices) {
  std::vector<uint32_t> parent(numVertices);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<char> used(numVertices, 0);
  for (const Tri& t : tris)
    for (int c = 0; c < 3; ++c) {
      used[t[c]] = 1;
      parent[find(t[c])] = find(t[(c + 1) % 3]);
    }
  int n = 0;
  for (uint32_t v = 0; v < numVertices; ++v) n += used[v] && find(v) == v;
  return n;
}

// Divergence theorem: positive for an outward-oriented closed surface.
inline double enclosedVolume(const std::vector<Vec3>& p, const std::vector<Tri>& tris) {
  double v = 0;
  for (const Tri& t : tris) v += dot(p[t[0]], cross(p[t[1]], p[t[2]]));
  return v / 6.0;
}

inline double triangleArea(const std::vector<Vec3>& p, const Tri& t) {
  return 0.5 * norm(cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]])));
}

inline double surfaceArea(const std::vector<Vec3>& p, const std::vector<Tri>& tris) {
  double a = 0;
  for (const Tri& t : tris) a += triangleArea(p, t);
  return a;
}

inline double minTriangleArea(const std::vector<Vec3>& p, const std::vector<Tri>& tris) {
  double a = INFINITY;
  for (const Tri& t : tris) a = std::min(a, triangleArea(p, t));
  return a;
}

// ---- Self-intersections, with exact predicates --------------------------------------------
// Coordinates are quantised to a 2^24 grid over the mesh's bounding box (int64), and every
// orientation is an exact integer determinant (__int128), so the verdict is exact for the
// quantised mesh (a displacement of at most 2^-25 of the box, far below the mesher's smallest
// features). A pair of triangles is improper when it meets anywhere but in a shared vertex or
// a shared edge: no shared vertex and any contact; one shared vertex and contact beyond it; a
// shared edge and the two triangles folded onto each other in one plane.
namespace exact {

using P = std::array<int64_t, 3>;

inline int sgn(__int128 v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

inline int orient3d(const P& a, const P& b, const P& c, const P& d) {
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

// Number of improper triangle pairs (0 for an embedded surface).
inline size_t selfIntersections(const std::vector<Vec3>& pos, const std::vector<Tri>& tris) {
  using exact::P;
  if (tris.empty()) return 0;
  Vec3 lo = pos[0], hi = pos[0];
  for (const Vec3& p : pos)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  const double scale = double(1 << 24) / extent;
  std::vector<P> q(pos.size());
  for (size_t i = 0; i < pos.size(); ++i)
    for (int k = 0; k < 3; ++k) q[i][k] = std::llround((pos[i][k] - lo[k]) * scale);
  // Buckets of a uniform grid over the triangles' boxes; a pair is tested once, in the bucket
  // holding the low corner of the overlap of the two boxes.
  double meanEdge = 0;
  for (const Tri& t : tris) meanEdge += norm(sub(pos[t[0]], pos[t[1]]));
  meanEdge /= double(tris.size());
  const int64_t cell = std::max<int64_t>(1, std::llround(2 * meanEdge * scale));
  std::vector<std::array<int64_t, 6>> box(tris.size());
  std::map<std::array<int64_t, 3>, std::vector<uint32_t>> buckets;
  for (size_t t = 0; t < tris.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      box[t][k] = std::min({q[tris[t][0]][k], q[tris[t][1]][k], q[tris[t][2]][k]});
      box[t][k + 3] = std::max({q[tris[t][0]][k], q[tris[t][1]][k], q[tris[t][2]][k]});
    }
    for (int64_t x = box[t][0] / cell; x <= box[t][3] / cell; ++x)
      for (int64_t y = box[t][1] / cell; y <= box[t][4] / cell; ++y)
        for (int64_t z = box[t][2] / cell; z <= box[t][5] / cell; ++z) buckets[{x, y, z}].push_back(uint32_t(t));
  }
  size_t bad = 0;
  for (const auto& [key, list] : buckets) {
    for (size_t i = 0; i < list.size(); ++i)
      for (size_t j = i + 1; j < list.size(); ++j) {
        const auto &A = box[list[i]], &B = box[list[j]];
        bool overlap = true;
        std::array<int64_t, 3> low;
        for (int k = 0; k < 3; ++k) {
          if (A[k] > B[k + 3] || B[k] > A[k + 3]) overlap = false;
          low[k] = std::max(A[k], B[k]) / cell;
        }
        if (!overlap || low != key) continue;
        const Tri &t = tris[list[i]], &u = tris[list[j]];
        int shared = 0, ti = -1, ui = -1;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            if (t[a] == u[b]) ++shared, ti = a, ui = b;
        std::array<P, 3> T{q[t[0]], q[t[1]], q[t[2]]}, U{q[u[0]], q[u[1]], q[u[2]]};
        bool improper = false;
        if (shared == 0) {
          improper = exact::triTri(T, U);
        } else if (shared == 1) {
          const P& v = T[ti];
          const P &a = T[(ti + 1) % 3], &b = T[(ti + 2) % 3], &c = U[(ui + 1) % 3], &d = U[(ui + 2) % 3];
          improper = exact::segTri(a, b, U[0], U[1], U[2]) || exact::segTri(c, d, T[0], T[1], T[2]) ||
                     exact::rayIntoCorner(v, a, c, d) || exact::rayIntoCorner(v, b, c, d) ||
                     exact::rayIntoCorner(v, c, a, b) || exact::rayIntoCorner(v, d, a, b);
        } else if (shared == 2) {
          // The vertices not shared; folded when coplanar and on the same side of the edge.
          int ta = 0, ub = 0;
          for (int a = 0; a < 3; ++a) {
            if (t[a] != u[0] && t[a] != u[1] && t[a] != u[2]) ta = a;
            if (u[a] != t[0] && u[a] != t[1] && u[a] != t[2]) ub = a;
          }
          const P &e0 = T[(ta + 1) % 3], &e1 = T[(ta + 2) % 3];
          if (exact::orient3d(e0, e1, T[ta], U[ub]) == 0) {
            int drop = exact::dropAxis(e0, e1, T[ta]);
            improper = exact::orient2d(drop, e0, e1, T[ta]) * exact::orient2d(drop, e0, e1, U[ub]) > 0;
          }
        } else {
          improper = true;  // the same triangle twice
        }
        bad += improper;
      }
  }
  return bad;
}

}  // namespace mesh_checks
