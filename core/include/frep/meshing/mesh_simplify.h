// Adaptive, feature-preserving simplification of a mesh of a model (docs/mesh.md, "Adaptivity
// and sharp features").
//
// Greedy edge collapses ordered by a quadric error built from the model's TANGENT PLANES at the
// mesher's vertices (points on the surface with the gradient's normal), not from the mesh's own
// triangles: where a crease or a corner of the model crosses the mesh, the quadric of the merged
// vertices holds the planes of the faces that meet there, so the merged vertex lands on the
// edge or the corner (the estimate of dual contouring's QEF), and flat regions merge freely.
//
// Each pass first contracts cells: the connected vertices of a grid cell of 1, 2, then 4 voxels
// merged into one at their quadric's least-squares point where the star stays a disk (dual
// contouring's vertex per cell, reached from the marching tetrahedra's mesh), with the same
// shape and error checks as an edge collapse on the fan; the greedy collapses do the rest.
//
// Every collapse is checked before it is made:
//  - topology: the link condition (the surface stays a closed 2-manifold, same genus);
//  - no fold, no degenerate triangle: no changed triangle turns by more than ~80 degrees or
//    gets thinner than a quality bound (unless it was already);
//  - no self-intersection: the new triangles against every triangle near them, with the exact
//    predicates of frep/meshing/mesh_predicates.h on positions quantised to 2^-16 voxel
//    (checked once on each block's result; a block that fails is simplified again with this
//    check at every collapse);
//  - error against the model itself: at points spread over each new triangle (at most half a
//    voxel apart, up to 64x64 points per triangle) the surface must be crossed within distance
//    e along the triangle's normal: f(p - e n) inside and f(p + e n) outside. e is the
//    tolerance, or the error the replaced triangles already had if larger (the mesher's chords
//    across a crease), so the result is never further from the surface than the tolerance or
//    the input mesh. The removed vertices must also stay within e of the new triangles.
// Passes: two of independent 32^3 blocks (fixed in index space; in parallel, and in the workers
// for the blocks inside their bricks: simplifyRegion), two of 64^3 blocks, then one over the
// whole mesh. Each is deterministic (ties broken by vertex index) and starts from the canonical
// mesh, so the output depends only on the input mesh: the farm's split-invariance carries over.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "frep/meshing/mesh.h"

namespace frep {

// The tolerances simplification takes (voxels): 0 (off) or within [kMinSimplifyTolerance,
// kMaxSimplifyTolerance]. Its error levels tolerance * voxel * 2^k and their squares must be
// normal numbers: 5e-324 or an infinity would loop without end. Others throw invalid_argument.
constexpr double kMinSimplifyTolerance = 1e-30;
constexpr double kMaxSimplifyTolerance = 1e30;

struct SimplifyOptions {
  double tolerance = 0;  // in voxels (grid.voxel); <= 0: the mesh is left as it is
  // true: a merged vertex goes where its quadric is least (on edges and corners of the model);
  // false: it stays at one of the two vertices (every vertex remains a root on a grid edge).
  bool sharpFeatures = true;
  std::vector<double> fixedCoords;  // x[3], x[4], ... for models of dimension > 3
  double minQuality = 0.02;  // 4 sqrt(3) area / sum of squared edges (1: equilateral)
  int threads = 0;           // the block passes' independent blocks; 0: all cores (same result)
  // The error check's signs in float where a certified bound decides them, in double for the
  // rest (frep/evaluators/float_error.h; tapes it does not cover: double throughout). Never
  // changes the result; false: double throughout (for tests).
  bool floatSigns = true;
  // A level of many samples first tried by interval bounds of the model over the two boxes its
  // samples lie in (simplifier.h, offsetsDecided), where the tape's interval extension holds its
  // double values. Never changes the result; false: every sample evaluated (for tests).
  bool intervalLevels = true;
  // The mesh's bricks of this many cells (from index 0) went through simplifyRegion already:
  // their blocks are not done again. 0: none.
  int bricksSimplified = 0;
  // Called as simplifyMesh advances (from the block passes' threads too: it must be thread-safe):
  // stages 0 to 3 are the block passes (blocks done of total), stage 4 the global pass
  // (collapse candidates examined of examined + queued, so its total grows). Never changes the
  // result.
  std::function<void(int stage, uint64_t done, uint64_t total)> progress;
  // Cancel (checked every 1024 candidates and every block) and progress ("simplify": the global
  // pass's candidates examined of examined + queued); null: the caller's.
  const Interrupter* interrupt = nullptr;
};

struct SimplifyStats : SimplifyCounters {
  uint64_t trianglesBefore = 0, trianglesAfter = 0;
  double errorBound = 0;  // in world units: no output triangle is further from the surface
                          // (measured along its normal at the check points)
};

// Simplifies `mesh` (merged from pieces, maybe with their carry) in place.
SimplifyStats simplifyMesh(Mesh& mesh, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& options);

// The share of one region [lo, hi) of cells (a farm brick) that needs nothing outside it: the
// block passes' blocks that lie inside it. The piece stays a valid piece (vertices by key,
// canonical triangles, the seam vertices untouched) and carries what simplifyMesh needs to
// finish; merged and finished with options.bricksSimplified = the brick edge, the result is the
// same mesh as simplifyMesh of the raw merged mesh.
void simplifyRegion(MeshPiece& piece, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& options,
                    const std::array<int32_t, 3>& lo, const std::array<int32_t, 3>& hi);

// The error check's sample points of a triangle a, b, c split into m x m similar sub-triangles
// (m = ceil(2 longest edge / voxel), 1..64): cell (i, j) is the point
// a + (i + 1/3)(b - a)/m + (j + 1/3)(c - a)/m, the centroid of an upright sub-triangle; the
// probes (tried first) lead. Exposed for its test.
const std::vector<std::array<int32_t, 2>>& errorSampleCells(int m);

}  // namespace frep
