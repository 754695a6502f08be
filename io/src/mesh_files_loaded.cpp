// meshFilesBackend() for frep: the 3MF and glTF writers loaded from libfrep_mesh_files.so the
// first time a job writes a .3mf or a .glb (mesh_writers.h says why). Linked into the program as
// an object file, so the linker takes this definition and never the archive's linked one.
#include "frep/io/program_module.h"
#include "mesh_writers.h"

namespace frep::io::detail {

const MeshFilesBackend& meshFilesBackend() {
  // Thread-safe; a throw leaves it to be tried again.
  static const auto* const backend = static_cast<const MeshFilesBackend*>(
      loadProgramModule("libfrep_mesh_files.so", kMeshFilesModuleEntry, sizeof(MeshFilesBackend),
                        "frepfarm's mesh file module (needed for .3mf and .glb files)"));
  return *backend;
}

}  // namespace frep::io::detail
