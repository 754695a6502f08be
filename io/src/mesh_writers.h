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

// The 3MF and glTF writers link lib3MF and tinygltf (with libzip, libcrypto and stb: a third of
// a small `frep mesh` run's start, frep/io/program_module.h), so writeMesh reaches them through
// this table: frep loads it from libfrep_mesh_files.so when a job writes such a file
// (mesh_files_loaded.cpp, whose definition the linker takes first), frep_io, the Python module
// and the tests link them in (mesh_files_linked.cpp).
struct MeshFilesBackend {
  void (*write3mf)(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);
  void (*writeGlb)(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);
};
const MeshFilesBackend& linkedMeshFiles();   // this binary's writers (mesh_files_linked.cpp)
const MeshFilesBackend& meshFilesBackend();  // the table this program uses
inline constexpr const char* kMeshFilesModuleEntry = "frep_mesh_files_backend";

// A [0, 1] channel as a byte (0..255, rounded to the nearest).
inline uint8_t channelByte(float c) { return uint8_t(std::lround(double(c) * 255.0)); }

}  // namespace frep::io::detail
