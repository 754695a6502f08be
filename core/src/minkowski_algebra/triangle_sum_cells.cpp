// The cells T ⊕ B of a mesh's triangles and a convex piece (triangle_sum_cells.h).
#include "triangle_sum_cells.h"

#include <algorithm>
#include <cmath>

namespace frep::minkowski {

using namespace vec3;
using namespace mesh_operands;

namespace {

// Whether the supporting plane of T ⊕ B of normal u (T's and B's support hT, hB) holds a
// facet: the corners of T and of B within tol of their support span two directions. Near-ties
// count as ties, so a doubtful plane is kept (a supporting plane is never wrong, only slow).
bool isFacet(const V3 tv[3], const Convex& b, const V3& u, double hT, double hB, double tol) {
  V3 first{};  // the first direction found
  bool have = false;
  auto add = [&](const V3& d) {  // true: d and the first span two directions, a facet
    const double l2 = dot(d, d);
    if (!(l2 > tol * tol)) return false;
    if (!have) {
      first = d, have = true;
      return false;
    }
    const V3 c = cross(first, d);
    return dot(c, c) > 1e-20 * dot(first, first) * l2;
  };
  const V3* t0 = nullptr;
  for (int k = 0; k < 3; ++k)
    if (dot(u, tv[k]) >= hT - tol) {
      if (!t0) t0 = &tv[k];
      else if (add(sub(tv[k], *t0))) return true;
    }
  const V3* b0 = nullptr;
  for (const V3& p : b.v)
    if (dot(u, p) >= hB - tol) {
      if (!b0) b0 = &p;
      else if (add(sub(p, *b0))) return true;
    }
  return false;
}

}  // namespace

std::vector<V3> edgeDirections(const Convex& b) {
  std::vector<V3> bDirs;
  for (const auto& e : b.edges) {
    V3 d = sub(b.v[e[1]], b.v[e[0]]);
    const double l = norm(d);
    if (!(l > 0)) continue;
    for (double& x : d) x /= l;
    bool known = false;
    for (const V3& k : bDirs) known = known || std::abs(dot(k, d)) > 1 - 1e-12;
    if (!known) bDirs.push_back(d);
  }
  return bDirs;
}

void TriangleSumCells::add(const Mesh& a, const Convex& b, const std::vector<V3>& bDirs, double tol) {
  V3 bLo{INFINITY, INFINITY, INFINITY}, bHi{-INFINITY, -INFINITY, -INFINITY};  // B's box
  for (const V3& p : b.v)
    for (size_t k = 0; k < 3; ++k) bLo[k] = std::min(bLo[k], p[k]), bHi[k] = std::max(bHi[k], p[k]);
  // B's facet normals, one per plane (a triangulated face gives several triangles).
  std::vector<V3> bNormals;
  for (const V3& n : b.faceN) {
    bool known = false;
    for (const V3& k : bNormals) known = known || dot(k, n) > 1 - 1e-12;
    if (!known) bNormals.push_back(n);
  }
  // A B with no facets is a segment or a point (a path's piece); one with facets has volume.
  const bool flatB = bNormals.empty();
  std::vector<V3> normals;
  std::vector<std::array<double, 4>> touching;
  for (const auto& t : a.t) {
    const V3 tv[3] = {a.v[t[0]], a.v[t[1]], a.v[t[2]]};
    // The candidate facet normals of T ⊕ B, each once: two within 1e-12 are one (rounding), but
    // not two that are merely close, such as the facets of a prism T ⊕ d a hair off T's plane
    // and ±n_T (merged, the thin slanted prism would read as the flat box over its shadow).
    normals.clear();
    auto candidate = [&](V3 u) {
      const double l = norm(u);
      if (!(l > 0)) return;
      for (double& x : u) x /= l;
      for (const V3& k : normals)
        if (dot(sub(k, u), sub(k, u)) < 1e-24) return;
      normals.push_back(u);
    };
    const V3 n = cross(sub(tv[1], tv[0]), sub(tv[2], tv[0]));
    const double ln = norm(n);
    // A flat B (a segment of a path, path_sweep.h): a T of no area adds no cell (its points lie
    // on its neighbours, and no finite set of planes bounds a segment ⊕ segment's points).
    if (flatB && !(ln > 0)) continue;
    candidate(n);
    candidate({-n[0], -n[1], -n[2]});
    for (const V3& u : bNormals) candidate(u);
    for (int k = 0; k < 3; ++k) {
      const V3 eT = sub(tv[(k + 1) % 3], tv[k]);
      for (const V3& d : bDirs) {
        const V3 u = cross(eT, d);
        if (!(norm(u) > 1e-12 * norm(eT))) continue;  // parallel: the sum of the edges is a segment
        candidate(u);
        candidate({-u[0], -u[1], -u[2]});
      }
    }
    // A flat B parallel to T's plane makes T ⊕ B flat too, a polygon whose edges are T's and B's:
    // its planes are ±n_T and the in-plane normals n_T × e of those edges, which the products
    // above miss (there they are ±n_T). Supporting planes are exact wherever they point, so they
    // are added whenever B lies within 1e-5 of T's plane (a prism that thin has them all,
    // redundant or not), so no B in T's plane up to rounding goes without them.
    bool parallel = flatB;
    for (const V3& d : bDirs) parallel = parallel && std::abs(dot(n, d)) < 1e-5 * ln;
    if (parallel) {
      auto inPlane = [&](const V3& e) {
        const V3 u = cross(n, e);
        candidate(u);
        candidate({-u[0], -u[1], -u[2]});
      };
      for (int k = 0; k < 3; ++k) inPlane(sub(tv[(k + 1) % 3], tv[k]));
      for (const V3& d : bDirs) inPlane(d);
    }
    // The facets of T ⊕ B first, the planes that touch it in an edge or a corner after: the
    // queries' c_T needs only the facets (inside a convex polytope the nearest of its
    // supporting planes is a facet's, so the min is the same), the lists' separation test
    // takes all (a corner's plane may separate a lattice cell that no facet does). A flat sum
    // (B parallel to T) keeps all: its edges' planes bound it within its plane.
    const uint32_t first = uint32_t(planes.size());
    touching.clear();
    for (const V3& u : normals) {
      const double hT = std::max({dot(u, tv[0]), dot(u, tv[1]), dot(u, tv[2])}), hB = b.support(u);
      const std::array<double, 4> plane{u[0], u[1], u[2], hT + hB};
      if (parallel || isFacet(tv, b, u, hT, hB, tol)) planes.push_back(plane);
      else touching.push_back(plane);
    }
    const uint32_t facets = uint32_t(planes.size()) - first;
    planes.insert(planes.end(), touching.begin(), touching.end());
    cells.push_back({first, facets, uint32_t(planes.size()) - first});
    Bvh::Box box;
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = std::min({tv[0][size_t(k)], tv[1][size_t(k)], tv[2][size_t(k)]}) + bLo[size_t(k)] - tol;
      box.hi[k] = std::max({tv[0][size_t(k)], tv[1][size_t(k)], tv[2][size_t(k)]}) + bHi[size_t(k)] + tol;
    }
    boxes.push_back(box);
  }
}

}  // namespace frep::minkowski
