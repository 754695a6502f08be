// The operands of the mesh ⊕ polytope sums (mesh_convex_sum.cpp): a closed mesh read from a
// mesh field or a convex polytope's boundary, and a closed mesh as a convex body.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/geometry/vec3.h"

namespace frep::minkowski::mesh_operands {

using V3 = Vec3;

// A closed triangle mesh in world coordinates.
struct Mesh {
  std::vector<V3> v;
  std::vector<std::array<uint32_t, 3>> t;
  std::string what;
};

// B as the convex polytope of a closed mesh: vertices, outward facet planes, edge directions.
struct Convex {
  std::vector<V3> v;
  std::vector<std::array<V3, 3>> faces;        // triangles
  std::vector<V3> faceN;                       // unit outward normals
  std::vector<std::array<uint32_t, 2>> edges;  // unique edges between non-coplanar faces
  double support(const V3& u) const {
    double h = -INFINITY;
    for (const V3& p : v) h = std::max(h, vec3::dot(u, p));
    return h;
  }
};

// The closed mesh of e in world coordinates: a mesh field read through a scaling and shift of
// each axis, or a convex polytope's boundary (isPolytope); nothing otherwise.
std::optional<Mesh> closedMeshOf(const Expr& e, bool* isPolytope);
// The largest coordinate magnitude of pts (a scale for tolerances).
double extentOf(const std::vector<V3>& pts);
// The mesh as a convex body, or nothing when some vertex lies outside a face's plane.
std::optional<Convex> convexOf(const Mesh& m, double scale);
// m scaled about the origin by s, its description saying so.
void scaleMesh(Mesh& m, double s);

}  // namespace frep::minkowski::mesh_operands
