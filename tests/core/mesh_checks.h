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

#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_predicates.h"

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
  return frep::closureDefect(tris, numVertices);  // the check frep mesh runs before it writes
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

// Vertices not certified within `radius` of the surface {f = 0} (inside: f >= 0): none of the
// vertex itself, +-normal and the 26 grid directions at that distance gives both an inside and
// an outside point (when some do, the segment between them, inside the ball, crosses it).
template <typename F>
size_t verticesFarFromSurface(const std::vector<Vec3>& pos, const std::vector<Vec3>& normals, double radius, F&& f) {
  size_t far = 0;
  for (size_t i = 0; i < pos.size(); ++i) {
    bool in = false, out = false;
    auto probe = [&](double dx, double dy, double dz) {
      double len = std::sqrt(dx * dx + dy * dy + dz * dz);
      double s = len > 0 ? radius / len : 0;
      (f(Vec3{pos[i][0] + s * dx, pos[i][1] + s * dy, pos[i][2] + s * dz}) >= 0 ? in : out) = true;
    };
    probe(0, 0, 0);
    probe(normals[i][0], normals[i][1], normals[i][2]);
    probe(-normals[i][0], -normals[i][1], -normals[i][2]);
    for (int d = 0; d < 27 && !(in && out); ++d)
      if (d != 13) probe(d / 9 - 1, (d / 3) % 3 - 1, d % 3 - 1);
    far += !(in && out);
  }
  return far;
}

// ---- Self-intersections, with exact predicates --------------------------------------------
// Coordinates are quantised to a 2^24 grid over the mesh's bounding box (int64), and every
// orientation is an exact integer determinant (__int128), so the verdict is exact for the
// quantised mesh (a displacement of at most 2^-25 of the box, far below the mesher's smallest
// features). A pair of triangles is improper when it meets anywhere but in a shared vertex or
// a shared edge: no shared vertex and any contact; one shared vertex and contact beyond it; a
// shared edge and the two triangles folded onto each other in one plane (frep/meshing/mesh_predicates.h).

// Number of improper triangle pairs (0 for an embedded surface).
inline size_t selfIntersections(const std::vector<Vec3>& pos, const std::vector<Tri>& tris) {
  using P = frep::exact::P;
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
        bool improper = frep::improperPair(t, {q[t[0]], q[t[1]], q[t[2]]}, u, {q[u[0]], q[u[1]], q[u[2]]});
        bad += improper;
      }
  }
  return bad;
}

}  // namespace mesh_checks
