// The convex cells T ⊕ B of a closed mesh's triangles T and a convex piece B, as planes and
// boxes (mesh_convex_sum.cpp: A ⊕ B is the translate A + b0 and the union of these cells).
// Internal to frep_core.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frep/geometry/distance_fields.h"
#include "mesh_operands.h"

namespace frep::minkowski {

// B's edge directions, one per parallel class.
std::vector<Vec3> edgeDirections(const mesh_operands::Convex& b);

struct TriangleSumCells {
  struct Cell {
    uint32_t first, count, all;  // planes[first, first + count): its facets; to first + all: every plane
  };
  std::vector<std::array<double, 4>> planes;  // u . x <= h
  std::vector<Cell> cells;
  std::vector<Bvh::Box> boxes;  // each cell's box, grown by tol
  // The cells T ⊕ B of every triangle T of A (bDirs: edgeDirections(b)), appended.
  void add(const mesh_operands::Mesh& a, const mesh_operands::Convex& b, const std::vector<Vec3>& bDirs, double tol);
};

}  // namespace frep::minkowski
