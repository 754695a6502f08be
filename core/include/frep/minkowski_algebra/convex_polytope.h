// A solid written as an intersection of half-spaces, recognised as the convex polytope it is,
// so that Minkowski sums and differences with a ball take the exact offset path
// (distance_offset.h) instead of the extremum search, whatever the orientation of its planes.
//
// A field is such an intersection when its min/max form (min_max_form.h: R-functions and
// hfBlock's slab products become min, sign-exactly) is a min of affine functions of x, y, z:
// min_i (n_i . X + d_i) >= 0. The polytope's vertices are the feasible intersections of three
// planes; each plane that holds three or more of them is a facet, its vertices ordered around
// their centroid and fanned into outward triangles. The result is the closed triangle mesh's
// exact signed distance (MeshField), with the same set as the field: dist to a convex polytope
// has no closed form from its planes (min_i of the plane distances is exact inside only).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::minkowski {

struct ConvexPolytope {
  Expr field;  // the exact signed distance (positive inside) of the polytope, in closed form
               // up to 32 facets (registered as an exact distance), else `mesh`
  Expr mesh;   // the same distance as a field of the boundary mesh (for mesh algorithms)
  size_t planes = 0, facets = 0, vertices = 0;
  std::vector<std::array<double, 3>> corners;  // its vertices
};

// The polytope of `e` over x[0..2], or nothing when e is not (sign-exactly) a min of affine
// functions, holds more than 64 planes, or is empty, flat or unbounded.
std::optional<ConvexPolytope> convexPolytopeOf(const Expr& e);

// A union of convex polytopes: a min/max form (negations included) whose leaves are affine,
// e.g. hfBlock \ hfBlock. Its disjunctive normal form max_i min_j (n_ij . X + d_ij) is a union
// of intersections of half-spaces (min distributes over max; -min(a, b) = max(-a, -b)); empty
// and flat terms are dropped (the solid is regularised), the others become polytopes as above,
// an axis-aligned one (all its normals along axes, as hfBlock's) as a box with a closed-form
// distance. field = max_i of the pieces' exact signed distances: exact outside the union (the
// distance to a union is the least of the distances), a lower bound of the depth inside.
// Minkowski sums with a ball distribute over the union (Roerdink eq. 1) and take the offset path.
struct PolytopeUnion {
  Expr field;
  size_t pieces = 0, boxes = 0;                                // boxes: the pieces written in closed form
  bool exactInside = false;                                    // polytopeComplementOf's (else exact outside)
  std::vector<std::vector<std::array<double, 3>>> corners;     // each bounded piece's vertices
  std::vector<std::vector<std::array<double, 4>>> halfSpaces;  // and its n . X + d >= 0 (unit n)
  // Whether the pieces form one connected set (each meets another, transitively).
  bool connected() const;
  std::string describe() const;  // "union of 2 convex pieces (2 of them boxes)"
};

// Nothing when e is not such a form, needs more than 64 terms or 64 planes in one, or is
// unbounded or empty.
std::optional<PolytopeUnion> polytopeUnionOf(const Expr& e);

// The union of convex pieces given by their half-spaces n . X + d >= 0 (unit n), as above;
// nothing when a piece is unbounded or there are more than 64 pieces or planes in one.
std::optional<PolytopeUnion> polytopeUnionOfPieces(const std::vector<std::vector<std::array<double, 4>>>& pieces);

// A closed mesh operand (frMesh, up to 256 triangles) that is a convex polyhedron or is covered
// by at most 8 convex pieces (convex_cover.h), as the union of those polytopes: the mesh
// distance's set and exact distance outside it, in closed form (cheaper to evaluate than the
// mesh node, in batches and in float). `what` names the mesh. Nothing otherwise.
std::optional<PolytopeUnion> polytopeUnionOfMesh(const Expr& e, std::string* what);

// The same forms read from inside, for erosions: the complement of e's set is the union of the
// terms of -e's normal form (often unbounded: a half-space, a wedge, the outside of a block),
// and the distance to a union is the least of the distances to its pieces, so field = -(max_i
// of those pieces' exact signed distances) is exact inside e's set (an unbounded general piece
// is clipped by a box 10^6 times the planes' offsets away). Nothing when e is not such a form,
// outgrows the limits, or its complement is empty or everything.
std::optional<PolytopeUnion> polytopeComplementOf(const Expr& e);

}  // namespace frep::minkowski
