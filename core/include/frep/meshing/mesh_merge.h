// mergePieces (mesh.h) for the farm's master: the same merge, run while the pieces are released
// one by one, so it holds about one copy of the output instead of three (docs/mesh.md, "Memory").
#pragma once

#include <vector>

#include "frep/meshing/mesh.h"

namespace frep {

// Equal to mergePieces(pieces) (the same vertices, keys, normals, triangles and summed stats);
// every piece is left empty (its vectors freed) once it has been consumed. Throws
// std::invalid_argument for a piece whose vertices are not sorted by key or whose triangles
// index past its vertices.
Mesh mergePiecesReleasing(std::vector<MeshPiece>& pieces);

}  // namespace frep
