// mergePieces (mesh.h) for the farm's master: the same merge, run while the pieces are released
// one by one, so it holds about one copy of the output instead of three (docs/mesh.md, "Memory").
#pragma once

#include <vector>

#include "frep/meshing/mesh.h"

namespace frep {

// Equal to mergePieces(pieces) (the same vertices, keys, normals, triangles and summed stats);
// every piece is left empty (its vectors freed) once it has been consumed. Throws
// std::invalid_argument for a piece whose vertices are not sorted by key or whose triangles
// index past its vertices. trimHeap: hand the freed pieces back to the kernel (malloc_trim) as
// the merge goes; false in a process that keeps what it frees for the work that follows (the
// simplification reuses it instead of faulting in fresh pages; farm::applyAllocatorPolicy).
Mesh mergePiecesReleasing(std::vector<MeshPiece>& pieces, bool trimHeap = true);

}  // namespace frep
