// Meshing sampled values (no model): the surface {f = 0} of a sparse sampled grid such as the
// sampler's SampleResult or a FloatGrid written by `frep sample` and read back (cli/), by the
// same marching tetrahedra on the Kuhn grid as the model mesher (mesh.h), so the mesh is closed,
// 2-manifold and oriented outward exactly as meshGrid's is, with vertices keyed by the same
// global grid edges (docs/mesh.md, "Meshing a .vdb").
//
// What differs from meshGrid: there is no model to solve, so a vertex is the crossing of the
// linear interpolant of the two stored end values, and its normal is -grad f interpolated along
// the edge from the central-difference gradients of the stored values at the edge's ends.
//
// Which cells are meshed: the cells of the leaves whose 8 corners are all ACTIVE voxels (active
// voxels carry values; inactive voxels and tiles carry only a sign, +-band). A sampler band of
// at least one voxel makes every corner of every crossed cell active, so every crossed cell of
// the grid is meshed; a crossed cell with an inactive corner (only possible with a band of
// fewer than 1 voxel, or edited files) is counted in incompleteCells and left out.
#pragma once

#include <cstdint>

#include "frep/meshing/mesh.h"
#include "frep/sampling/sample.h"

namespace frep {

struct SampledMeshOptions {
  int threads = 0;        // 0: TBB's default; 1: serial (the result is the same)
  double endGuard = 1e-3;  // vertices stay this fraction of the edge away from its ends (as MeshOptions)
};

struct SampledMesh {
  Mesh mesh;                     // stats: cellsVisited, cellsCrossed (the other counters are 0)
  uint64_t incompleteCells = 0;  // crossed cells left out because a corner was inactive
};

// Meshes the sampled values (F-rep sign: inside when the value's sign bit is clear and it is not
// NaN, as meshGrid's sign rule). Positions are world coordinates grid.origin + index * voxel.
// Leaves must have distinct origins (multiples of 8); tiles give the sign of whole blocks for
// the gradients next to the band. The result does not depend on threads.
SampledMesh meshSamples(const SampleResult& samples, const SampledMeshOptions& options = {});

}  // namespace frep
