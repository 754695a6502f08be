// A closed mesh covered by a few convex pieces that may overlap, so that a sum with a
// non-convex tool runs on the exact mesh ⊕ polytope construction (mesh_convex_sum.h; issue 30).
// By Roerdink-Minkowski eq. 1, A ⊕ P = ∪_i (A ⊕ K_i) for any convex K_i ⊆ P with ∪_i K_i = P:
// the pieces need only cover P, so they can be much fuller than a partition (an L prism is two
// overlapping boxes, not ten pyramids from a kernel point).
//
// Cells: the tool's bounding box cut (a binary space partition) by the face planes of the
// reflex edges that meet a cell. A cell with no reflex edge inside holds a locally convex, hence
// convex (Tietze-Nakajima), part of the tool in each component: with one component, the cell
// cut by the tool faces reaching into it. It is kept when that lies in the tool (else halved),
// and the kept parts must add up to the tool's volume. Then from each cell a piece is grown by
// taking in touching cells while the hull stays in the tool, and a greedy set cover of the
// cells picks the pieces. No kernel point is needed, so tools that are not star-shaped (a U, a
// comb) are covered too.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "frep/geometry/vec3.h"
#include "frep/minkowski_algebra/star_pieces.h"

namespace frep::minkowski {

// The convex hull of pts as a closed, outward-oriented triangle mesh of its corners, or
// nothing when the points lie within tol of a plane. Points within tol of the hull may be left
// out of it.
std::optional<PieceMesh> convexHullMesh(const std::vector<Vec3>& pts, double tol);

// Whether the convex piece k (closed, outward) lies in the solid of the closed, outward mesh
// (v, t) up to tol: no triangle of the mesh reaches k shrunk by tol, and k's vertex centroid
// (at least 2 tol deep in k) is inside the mesh (winding number). Then k shrunk by tol lies in
// one component of the mesh's inside or outside, the inside one, so k is within tol of the tool.
bool convexInsideMesh(const PieceMesh& k, const std::vector<Vec3>& v, const std::vector<std::array<uint32_t, 3>>& t,
                      double tol);

// Convex pieces covering the solid of the closed, outward, connected mesh (v, t), or nothing
// when the mesh is convex, not connected, larger than 2048 triangles, would need more than
// maxCells cells or maxPieces pieces, or its cells' parts miss 10^-7 of its volume.
std::optional<std::vector<PieceMesh>> convexCover(const std::vector<Vec3>& v,
                                                  const std::vector<std::array<uint32_t, 3>>& t, size_t maxPieces,
                                                  size_t maxCells = 128);

}  // namespace frep::minkowski
