// Internal to io/src: the writers behind writeMesh, one per file (mesh_writer.cpp has PLY, OBJ,
// STL and POV; mesh_writer_vrml.cpp, mesh_writer_3mf.cpp, mesh_writer_glb.cpp the others). The
// mesh is already in the file's axes.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "frep/io/mesh_writer.h"

namespace frep::io::detail {

void writeVrml(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);
void write3mf(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);
void writeGlb(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);

// A [0, 1] channel as a byte (0..255, rounded to the nearest).
inline uint8_t channelByte(float c) { return uint8_t(std::lround(double(c) * 255.0)); }

}  // namespace frep::io::detail
