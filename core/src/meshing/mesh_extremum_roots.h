// Internal to the mesher (mesh.cpp): vertices of the sign-changing edges of a model with extremum
// nodes, where every evaluation is a search (docs/mesh.md, "Models with extremum nodes").
#pragma once

#include <vector>

#include "frep/meshing/mesh.h"

namespace frep {

struct ExtremumEdge {
  EdgeKey key;
  bool inAtBase;  // the edge's base point is inside (the sign the cells were built from)
};

// One vertex per edge (vertices[i] for edges[i]): position by root finding on the model along the
// edge, started from its two end values and warm-started from the end's arg-extremum; normal from
// the model's values at the corners of the Kuhn tetrahedra around the edge. Every value comes
// from a cold search at a grid point or from a search warm-started along the edge itself, so a
// vertex is a function of its edge only. Adds to stats.rootEvals (searches on edges),
// samplePointEvals (searches at grid points) and fallbackEdges.
void extremumEdgeVertices(const TapePtr& tape, const GridSpec& grid, const MeshOptions& options,
                          const std::vector<ExtremumEdge>& edges, std::vector<MeshVertex>& vertices, MeshStats& stats);

}  // namespace frep
