// The convolution pieces of a mesh ⊕ convex sum (convolution_pieces.h).
#include "convolution_pieces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace frep::minkowski::mesh_operands {
namespace {

using namespace vec3;

// The convex hull of points on a plane with unit normal u, fanned into triangles (emit(p, q, r));
// nothing when they span no area (the face of a sum in a direction that is not a facet's).
template <typename Emit>
void facetTriangles(const V3& u, const std::vector<V3>& pts, double tol, Emit&& emit) {
  if (pts.size() < 3) return;
  const V3 e1 = std::abs(u[0]) < 0.9 ? cross(u, V3{1, 0, 0}) : cross(u, V3{0, 1, 0});
  const double l1 = norm(e1);
  const V3 a{e1[0] / l1, e1[1] / l1, e1[2] / l1}, b = cross(u, a);
  std::vector<std::pair<std::array<double, 2>, size_t>> q;
  for (size_t i = 0; i < pts.size(); ++i) q.push_back({{dot(a, pts[i]), dot(b, pts[i])}, i});
  std::sort(q.begin(), q.end());
  auto turn = [](const std::array<double, 2>& o, const std::array<double, 2>& p, const std::array<double, 2>& r) {
    return (p[0] - o[0]) * (r[1] - o[1]) - (p[1] - o[1]) * (r[0] - o[0]);
  };
  // Andrew's monotone chain; turns within tol * extent count as straight.
  std::vector<size_t> hull(2 * q.size());
  size_t k = 0;
  const double eps = tol * std::max(1.0, std::abs(q.back().first[0] - q.front().first[0]));
  for (size_t i = 0; i < q.size(); ++i) {
    while (k >= 2 && turn(q[hull[k - 2]].first, q[hull[k - 1]].first, q[i].first) <= eps) --k;
    hull[k++] = i;
  }
  for (size_t i = q.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(q[hull[k - 2]].first, q[hull[k - 1]].first, q[i].first) <= eps) --k;
    hull[k++] = i;
  }
  if (k < 4) return;  // fewer than three distinct corners (the chain repeats the first)
  for (size_t i = 1; i + 2 < k; ++i) emit(pts[q[hull[0]].second], pts[q[hull[i]].second], pts[q[hull[i + 1]].second]);
}

}  // namespace

void convolutionPieces(const Mesh& a, const Convex& b, const std::vector<V3>& bDirs, bool complement, double tol,
                       const EmitTriangle& tri) {
  const double sigma = complement ? -1 : 1;  // A^c's outward normals are A's reversed
  std::vector<V3> N(a.t.size());
  for (size_t i = 0; i < a.t.size(); ++i) {
    const auto& t = a.t[i];
    V3 n = cross(sub(a.v[t[1]], a.v[t[0]]), sub(a.v[t[2]], a.v[t[0]]));
    const double l = norm(n);
    N[i] = l > 0 ? V3{sigma * n[0] / l, sigma * n[1] / l, sigma * n[2] / l} : V3{0, 0, 0};
  }
  auto supportFace = [&](const V3& u, std::vector<V3>& out) {
    out.clear();
    const double h = b.support(u);
    for (const V3& q : b.v)
      if (dot(u, q) >= h - tol) out.push_back(q);
  };
  std::vector<V3> fb, pts;
  for (size_t i = 0; i < a.t.size(); ++i) {  // faces: T + F_B(N_T)
    if (N[i] == V3{0, 0, 0}) continue;
    supportFace(N[i], fb);
    pts.clear();
    for (uint32_t k : a.t[i])
      for (const V3& q : fb) pts.push_back(add(a.v[k], q));
    facetTriangles(N[i], pts, tol, tri);
  }
  // Edges: the two triangles of each (closed, consistently oriented mesh) and their far vertices.
  std::map<std::pair<uint32_t, uint32_t>, std::pair<size_t, uint32_t>> firstSide;
  std::vector<std::vector<uint32_t>> neighbours(a.v.size()), incident(a.v.size());
  for (size_t i = 0; i < a.t.size(); ++i) {
    const auto& t = a.t[i];
    for (int k = 0; k < 3; ++k) {
      const uint32_t p = t[size_t(k)], q = t[size_t((k + 1) % 3)], far = t[size_t((k + 2) % 3)];
      incident[p].push_back(uint32_t(i));
      neighbours[p].push_back(q);
      auto key = std::make_pair(std::min(p, q), std::max(p, q));
      auto it = firstSide.find(key);
      if (it == firstSide.end()) {
        firstSide.emplace(key, std::make_pair(i, far));
        continue;
      }
      const size_t j = it->second.first;
      const V3 &P = a.v[p], &Q = a.v[q], &w1 = a.v[it->second.second], &w2 = a.v[far];
      if (dot(N[j], sub(w2, P)) > tol) continue;  // reflex: the face pieces cover it
      const V3 e = sub(Q, P);
      for (const V3& d : bDirs) {
        V3 u = cross(e, d);
        const double l = norm(u);
        if (!(l > 1e-12 * norm(e))) continue;
        for (double sgn : {1.0, -1.0}) {
          const V3 us{sgn * u[0] / l, sgn * u[1] / l, sgn * u[2] / l};
          if (dot(us, sub(w1, P)) > tol || dot(us, sub(w2, P)) > tol) continue;  // not in the edge's arc
          const double hb = b.support(us);
          for (const auto& eb : b.edges) {
            const V3 &q0 = b.v[eb[0]], &q1 = b.v[eb[1]];
            if (dot(us, q0) < hb - tol || dot(us, q1) < hb - tol) continue;
            tri(add(P, q0), add(Q, q0), add(Q, q1));
            tri(add(P, q0), add(Q, q1), add(P, q1));
          }
        }
      }
    }
  }
  // Vertices.
  for (size_t v = 0; v < a.v.size(); ++v) {
    if (incident[v].empty()) continue;
    bool convex = true, concave = true;
    for (uint32_t f : incident[v])
      for (uint32_t w : neighbours[v]) {
        const double h = dot(N[f], sub(a.v[w], a.v[v]));
        convex = convex && h <= tol;
        concave = concave && h >= -tol;
      }
    if (concave && !convex) continue;
    for (size_t f = 0; f < b.faces.size(); ++f) {
      const V3& u = b.faceN[f];
      bool inCone = true;
      if (convex)
        for (uint32_t w : neighbours[v]) inCone = inCone && dot(u, sub(a.v[w], a.v[v])) <= tol;
      if (inCone) tri(add(a.v[v], b.faces[f][0]), add(a.v[v], b.faces[f][1]), add(a.v[v], b.faces[f][2]));
    }
  }
}

}  // namespace frep::minkowski::mesh_operands
