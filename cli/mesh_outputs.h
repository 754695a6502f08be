// The files frep mesh writes from one mesh: -O (format from its extension or --format) and
// hfp's -wrl/-stl/-stlb/-pov/-cli outputs, each through its own AtomicOutput; per-vertex colours
// when the model has them and a format holds them; CLI layer slices (-cli with -gs).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "frep/io/atomic_output.h"
#include "frep/io/mesh_writer.h"

namespace frep::cli {

struct MeshOutput {
  std::string path;
  bool slices = false, binarySlices = false;  // CLI layer slices instead of a mesh file
  io::MeshFormat format = io::MeshFormat::Ply;
  std::unique_ptr<io::AtomicOutput> file;
  std::string describe() const;  // "binary PLY", "CLI slices (ASCII)", ...
};

// Checks the paths, formats, --up and -gs before any work (CliError kExitBadArgs); then
// openMeshOutputFiles creates every temporary file (kExitIoError).
std::vector<MeshOutput> resolveMeshOutputs(const MeshRequest& request);
void openMeshOutputFiles(std::vector<MeshOutput>& outputs);
io::UpAxis upAxisOf(const MeshRequest& request);
bool wantsColours(const std::vector<MeshOutput>& outputs);

// Writes and commits every output. `box` (lo xyz, hi xyz) bounds the layers of CLI slices,
// `voxel` is their default thickness. Returns one line per file for the summary.
std::vector<std::string> writeMeshOutputs(std::vector<MeshOutput>& outputs, const Mesh& mesh, const MeshRequest& request,
                                          const std::string& name, const std::string& comment,
                                          const std::array<double, 6>& box, double voxel);

}  // namespace frep::cli
