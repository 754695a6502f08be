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

}  // namespace mesh_checks
