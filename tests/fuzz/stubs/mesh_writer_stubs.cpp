// The fuzz build compiles io/src/mesh_writer.cpp for povMesh2 (frep pov declares a tridiscsphere
// as a POV mesh2) without lib3mf and tinygltf: the writers it dispatches to but the targets never
// call are stubs here (in a folder of its own: the normal build's fuzz_corpus_tests links frep_io).
#include <stdexcept>

#include "mesh_writers.h"

namespace frep::io::detail {
namespace {
void notInFuzzBuild(const std::string&, const Mesh&, const MeshWriteOptions&) {
  throw std::logic_error("not in the fuzz build");
}
}  // namespace

void writeVrml(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options) {
  notInFuzzBuild(path, mesh, options);
}
const MeshFilesBackend& meshFilesBackend() {
  static const MeshFilesBackend table{notInFuzzBuild, notInFuzzBuild};
  return table;
}
}  // namespace frep::io::detail
