// Reading triangle meshes for frep render and frMesh: PLY (ascii, binary little or big endian; vertex x, y,
// z of any scalar type, other properties skipped; faces as lists, polygons fanned), OBJ (v and f
// lines, negative indices, v/vt/vn forms; polygons fanned; other lines ignored) and STL (binary
// when its size is what its facet count says, else ASCII when it starts with "solid"; ASCII
// must end with endsolid). Only positions and triangles are read. Every count is checked
// against the file's size before anything is allocated; coordinates must be finite; messages
// name the line or byte, never quote the file.
#pragma once

#include <string>

#include "frep/meshing/mesh.h"

namespace frep::io {

// Throws Error(kExitIoError) naming the file (and the line or element) when it cannot be read,
// is truncated, or is malformed (an index out of range, a non-finite coordinate, no triangles).
Mesh readMesh(const std::string& path);
// The same from bytes already read (frMesh: a model file's contents); `path` gives the format
// by its extension and names the file in messages.
Mesh parseMesh(const std::string& path, const std::string& bytes);

// The path's extension in lower case ("" if none): "Part.STL" -> "stl".
std::string lowerExtension(const std::string& path);

}  // namespace frep::io
