// Polygonisation of a model: a watertight, consistently oriented triangle mesh of {f = 0} that
// is the same, vertex for vertex and triangle for triangle, whatever the split of the grid into
// regions and the order in which the regions' pieces are merged (docs/mesh.md).
//
// Method: marching tetrahedra on the Kuhn (Freudenthal) decomposition of every grid cell into
// six tetrahedra around its main diagonal. Neighbouring cells triangulate their shared faces
// the same way, so the surface is closed and manifold by construction, with no ambiguous case.
// Only cells near the surface are visited (the sparse sampler's interval classification, band
// 1 voxel). Every vertex lies on a sign-changing grid edge (axis edge, face diagonal or body
// diagonal) and is keyed by that GLOBAL edge; its position comes from root finding on the model
// along the edge (Illinois, with bisection as the fallback), its normal from the gradient
// evaluator (outward = -grad f, inside is f >= 0). Models with extremum nodes, where every
// evaluation is a search, share grid-point values between edges instead (MeshOptions::
// extremumVertices, mesh_extremum_roots.cpp).
//
// Sign rule: a grid point is inside when f >= 0 (both zeros inside; NaN and negative values
// outside), so every edge has a strict sign change or none.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "frep/sampling/sample.h"
#include "frep/expressions/tape.h"

namespace frep {

// A grid edge from point (i, j, k) to (i, j, k) + d, where d's bits are the axis steps
// (bit 0: +x, bit 1: +y, bit 2: +z; 1..7). Keys order edges by (i, j, k, d), i.e. the
// vertex order of merged meshes. Indices must be below 2^19 per axis.
using EdgeKey = uint64_t;
inline EdgeKey edgeKey(int64_t i, int64_t j, int64_t k, int dir) {
  return (uint64_t(i) << 41) | (uint64_t(j) << 22) | (uint64_t(k) << 3) | uint64_t(dir);
}
inline std::array<int64_t, 4> edgeKeyParts(EdgeKey key) {
  return {int64_t(key >> 41), int64_t((key >> 22) & 0x7ffff), int64_t((key >> 3) & 0x7ffff), int64_t(key & 7)};
}
constexpr int64_t kMaxMeshGridPoints = int64_t(1) << 19;

// The sign rule (insideValue, storedValue) is in frep/sampling/sample.h.


// Rotates a triangle (winding kept) to start at its smallest index: the canonical form of the
// triangles of MeshPiece and Mesh.
inline void canonicalRotate(std::array<uint32_t, 3>& t) {
  if (t[1] < t[0] && t[1] < t[2]) t = {t[1], t[2], t[0]};
  else if (t[2] < t[0] && t[2] < t[1]) t = {t[2], t[0], t[1]};
}

struct MeshVertex {
  EdgeKey key;
  std::array<double, 3> position;
  std::array<double, 3> normal;  // unit, outward (towards decreasing f)
};

struct MeshStats {
  uint64_t cellsVisited = 0;    // cells whose 8 corner signs were examined
  uint64_t cellsCrossed = 0;    // cells with a sign change
  uint64_t rootEvals = 0;       // model evaluations of the edge root finding
  uint64_t gradientEvals = 0;   // normals
  uint64_t samplePointEvals = 0;  // evaluations of the band sampling (grid points)
  uint64_t fallbackEdges = 0;   // edges whose end values disagreed with their signs (bisection)
  // The band sampling's: NaN grid values and documented domain-error values. Not in the farm's
  // mesh payload: workers send them in the result message, as for `frep sample`.
  uint64_t sampleIntervalEvals = 0, nanValues = 0;
  DomainCounts domainErrors;
};

// The simplifier's work counters (mesh_simplify.h), summed over passes, blocks and bricks.
struct SimplifyCounters {
  uint64_t collapses = 0, rejectedTopology = 0, rejectedShape = 0, rejectedError = 0, rejectedIntersection = 0;
  uint64_t modelEvals = 0;
  SimplifyCounters& operator+=(const SimplifyCounters& o) {
    collapses += o.collapses, rejectedTopology += o.rejectedTopology, rejectedShape += o.rejectedShape;
    rejectedError += o.rejectedError, rejectedIntersection += o.rejectedIntersection, modelEvals += o.modelEvals;
    return *this;
  }
};

// What a region's simplification (simplifyRegion, mesh_simplify.h) leaves for the passes after
// it; empty for a mesh as the mesher made it. Indices are into the owner's vertices/triangles.
struct SimplifyCarry {
  // A vertex's quadric (A: xx xy xz yy yz zz, b: 3, c, weight), whether it left the mesher's
  // root, and the tag of the block run that settled it (0: none; mesh_simplify.cpp's
  // Work::settled); listed (by increasing index) only where that is more than its own tangent
  // plane, unmoved and unsettled.
  struct Vertex {
    uint32_t index;
    std::array<double, 11> quadric;
    uint8_t moved;
    uint32_t settled = 0;
  };
  std::vector<Vertex> vertices;
  // Per triangle (all of them, or none): error level + 1 (0: not measured), | 0x80 when a
  // collapse made it.
  std::vector<uint8_t> triangles;
  SimplifyCounters counters;  // the work done (summed into the final SimplifyStats)
};

// The triangles of one region: vertices keyed by global edges (sorted by key, unique), triangles
// as index triples into `vertices` (winding outward; each rotated to start at its smallest index,
// sorted). Pieces of adjacent regions share the vertices of the edges on their common boundary,
// with identical positions and normals; only the keys matter when pieces are merged.
struct MeshPiece {
  std::array<int32_t, 3> regionLo{0, 0, 0};
  std::vector<MeshVertex> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  MeshStats stats;
  SimplifyCarry carry;  // set by simplifyRegion
};

// One indexed mesh. Vertex order is the order of their keys, triangle order is the order of
// their key triples (each rotated to start at its smallest key, winding kept).
struct Mesh {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 3>> normals;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<EdgeKey> keys;  // the global edge of each vertex
  // Per-vertex colour (red, green, blue in [0, 1]) or empty: filled after the merge and the
  // simplification by colourMesh (frep/attributes/colour.h), so it never depends on the split.
  std::vector<std::array<float, 3>> colours;
  MeshStats stats;            // sums over the pieces
  SimplifyCarry carry;        // the pieces' (mergePieces keeps it with its vertices and triangles)
};

struct MeshOptions {
  std::vector<double> fixedCoords;  // values of x[3], x[4], ... for models of dimension > 3
  int threads = 0;                  // 0: TBB's default; 1: serial (the result is the same)
  int rootIterations = 10;          // Illinois steps per edge after its two end values
  // An edge's root search stops once |f| <= this. Negative (the default): 1% of the smallest
  // branch-and-bound tolerance among the model's extremum nodes (0 for models without them):
  // their searches' values are certified only that far, and each step costs a search.
  double rootStopValue = -1.0;
  // Models with extremum nodes: vertices from shared grid-point values and warm-started searches
  // along the edge, normals from those values (mesh_extremum_roots.cpp, docs/mesh.md); false: the
  // generic root finder and gradient above (about 5x the searches; kept for comparison).
  bool extremumVertices = true;
  // Roots are kept at least this fraction of the edge away from its ends, so no two vertices
  // coincide and no triangle is degenerate (the surface moves by at most this much).
  double endGuard = 1e-3;
  // Cancel and progress ("mesh": leaves' vertex groups started of total); null: the caller's.
  const Interrupter* interrupt = nullptr;
};

// Triangles of the cells whose minimum corner is in [lo, hi) (index space; lo a multiple of 8,
// hi clipped to the grid). Each cell belongs to exactly one region, so the pieces of a partition
// of the grid never produce a triangle twice.
MeshPiece meshRegion(const TapePtr& tape, const GridSpec& grid, const std::array<int32_t, 3>& lo,
                     const std::array<int32_t, 3>& hi, const MeshOptions& options = {});

// Every directed edge (a, b) of a triangle occurs exactly once and its reverse (b, a) occurs too:
// the surface is closed, 2-manifold at its edges and consistently oriented. Returns "" or the
// first problem found (edges in index order), and counts the unpaired directed edges.
std::string closureDefect(const std::vector<std::array<uint32_t, 3>>& triangles, size_t numVertices,
                          uint64_t* unpaired = nullptr);

// A bound on the distance from any point of a mesh as the mesher made it to the model's surface:
// every point of a triangle is within L / sqrt(3) of one of its corners (L its longest edge: the
// circumradius bound, half L for an obtuse triangle), and every corner is a root of the model on
// its grid edge, moved off the edge's end by at most endGuard of the edge (sqrt(3) voxels for the
// body diagonal) and, for a model with extremum nodes, placed where the search's value is within
// its tolerance of 0 (a distance where |grad f| >= 1 near the surface, as for distance operands).
// Triangles that a collapse made (flagged in mesh.carry) are left to the simplifier's bound.
double rawMeshErrorBound(const Mesh& mesh, const Tape& tape, const GridSpec& grid, double endGuard = 1e-3);

// Stitches pieces by key into one mesh, independent of the pieces' order and of the split.
// Throws std::invalid_argument for a piece whose vertices are not sorted by key or whose
// triangles index past its vertices. The same code as mergePiecesReleasing (mesh_merge.h).
Mesh mergePieces(const std::vector<MeshPiece>& pieces);

// The whole grid, split into cubic regions of `brick` voxels (a multiple of 8; 0: one region).
Mesh meshGrid(const TapePtr& tape, const GridSpec& grid, const MeshOptions& options = {}, int brick = 0);

}  // namespace frep
