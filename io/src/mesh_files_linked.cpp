// The 3MF and glTF writers' table (mesh_writers.h), and the table of a binary with them linked
// in. frep links mesh_files_loaded.cpp's meshFilesBackend() instead, so the linker never takes
// this file, nor lib3MF and tinygltf, into it; the module libfrep_mesh_files.so returns the table.
#include "mesh_writers.h"

namespace frep::io::detail {

const MeshFilesBackend& linkedMeshFiles() {
  static const MeshFilesBackend table{write3mf, writeGlb};
  return table;
}

const MeshFilesBackend& meshFilesBackend() { return linkedMeshFiles(); }

}  // namespace frep::io::detail
