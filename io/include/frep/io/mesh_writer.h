// Mesh files: binary PLY (default; positions and vertex normals), OBJ (v, vn, f with normals)
// and binary STL (facet normals). Positions and normals are written as 32-bit floats (OBJ prints
// the same float values with 9 significant digits, so every format reads back the same numbers).
#pragma once

#include <string>

#include "frep/meshing/mesh.h"

namespace frep::io {

enum class MeshFormat { Ply, Obj, Stl, Pov };  // Pov: mesh2 declared as frep_mesh (.inc/.pov)

// From the output file's extension (.ply, .obj, .stl; any case). Throws Error(kExitBadArgs)
// naming `field`.
MeshFormat meshFormatFromPath(const std::string& field, const std::string& path);
const char* meshFormatName(MeshFormat format);

// Writes `mesh` to `path` (the caller's temporary file). `comment` goes into the PLY/OBJ header
// and the STL header (truncated to its 80 bytes). Throws Error(kExitIoError).
void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format, const std::string& comment);

}  // namespace frep::io
