// frep mesh: the model's surface as a watertight, consistently oriented triangle mesh (core
// mesher, marching tetrahedra on the Kuhn grid; see docs/mesh.md), computed brick by brick on
// the farm like frep sample (workers run meshRegion on their bricks, the master stitches the
// pieces by global edge keys), so the file does not depend on --workers, --brick or --threads.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "arg_parse.h"
#include "atomic_output.h"
#include "commands.h"
#include "exit_codes.h"
#include "farm_job.h"
#include "frep/mesh.h"
#include "mesh_writer.h"
#include "sampling_grid.h"

namespace frep::cli {

int runMesh(const MeshRequest& request) {
  if (request.region.out.empty()) throw badArgs("-O/--out: the output mesh path (.ply, .obj or .stl) is required");
  MeshFormat format = meshFormatFromPath("-O/--out", request.region.out);
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  farm::FarmOptions options = farmOptions(request.farm, request.region.out, request.logLevel, request.threads);
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 128);
  LoadedModel m = loadModel(request.model, true);
  if (m.dims != 3)
    throw badArgs("frep mesh needs a three-dimensional object; '" + m.model.objectName + "' has " +
                  std::to_string(m.dims) + " coordinate(s) (map them with -x)");
  GridSpec grid = makeGrid(box, 3, res);
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] < 2 || grid.dims[a] >= kMaxMeshGridPoints)
      throw badArgs("--res/-g: the grid needs 2 to " + std::to_string(kMaxMeshGridPoints - 1) + " points per axis");

  AtomicOutput out("-O/--out", request.region.out);
  AtomicOutput reportOut("-O/--out (report)", request.region.out + ".report.json");
  farm::JobSpec job = makeJob(m, request.model.path, grid, "mesh");
  job.mutable_mesh()->set_sharp_features(request.sharp);
  spdlog::info("meshing '{}' on {}x{}x{} points of {}", m.model.objectName, grid.dims[0], grid.dims[1], grid.dims[2],
               grid.voxel);
  const auto start = std::chrono::steady_clock::now();
  farm::FarmOutcome outcome = runFarmJob(job, options);
  const farm::FarmReport& report = outcome.report;
  requireComplete(reportOut, report);
  const Mesh& mesh = outcome.mesh;
  const double meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string comment = "frep mesh of '" + m.model.objectName + "', grid " + std::to_string(grid.dims[0]) + "x" +
                        std::to_string(grid.dims[1]) + "x" + std::to_string(grid.dims[2]) + " voxel " +
                        formatNumber(grid.voxel) + "; normals point outward (decreasing f)";
  writeMesh(out.tempPath(), mesh, format, comment);
  out.commit();
  writeReport(reportOut, report);
  std::remove(options.journalPath.c_str());  // the output is complete: nothing to resume
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const MeshStats& s = mesh.stats;
  const double dense = double(grid.dims[0] - 1) * double(grid.dims[1] - 1) * double(grid.dims[2] - 1);
  std::ostream& text = request.farm.json ? std::cerr : std::cout;
  text << "wrote " << request.region.out << " (" << meshFormatName(format) << "): " << mesh.positions.size()
       << " vertices, " << mesh.triangles.size() << " triangles\n"
       << "  grid " << grid.dims[0] << "x" << grid.dims[1] << "x" << grid.dims[2] << " points of "
       << formatNumber(grid.voxel) << ", cells examined " << s.cellsVisited << " ("
       << formatNumber(std::round(1e4 * double(s.cellsVisited) / dense) / 100) << "% of " << uint64_t(dense)
       << "), crossed " << s.cellsCrossed << "\n"
       << (request.sharp ? "  feature vertices " + std::to_string(s.featureCells) + "\n" : std::string())
       << "  evaluations: grid points " << s.samplePointEvals << ", root finding " << s.rootEvals << ", gradients "
       << s.gradientEvals << "\n"
       << "  time " << formatNumber(std::round(meshSeconds * 1000) / 1000) << " s meshing, "
       << formatNumber(std::round(seconds * 1000) / 1000) << " s in all\n"
       << "  " << bricksSummary(report) << "\n"
       << "  report " << request.region.out << ".report.json\n";
  if (request.farm.json)
    std::cout << "{\"event\":\"done\",\"output\":\"" << request.region.out << "\",\"report\":\"" << request.region.out
              << ".report.json\"}\n";
  return kExitOk;
}

}  // namespace frep::cli
