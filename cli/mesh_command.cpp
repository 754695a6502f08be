// frep mesh: the model's surface as a watertight, consistently oriented triangle mesh (core
// mesher, marching tetrahedra on the Kuhn grid; see docs/mesh.md), computed brick by brick on
// the farm like frep sample (workers run meshRegion on their bricks, the master stitches the
// pieces by global edge keys), so the file does not depend on --workers, --brick or --threads.
#include <spdlog/spdlog.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "frep/farm/allocator_tuning.h"
#include "arg_parse.h"
#include "frep/worker/job_model.h"
#include "frep/io/atomic_output.h"
#include "commands.h"
#include "exit_codes.h"
#include "farm_job.h"
#include "frep/attributes/colour.h"
#include "json_events.h"
#include "frep/master/progress.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/io/mesh_writer.h"
#include "frep/meshing/mesh_grid.h"
#include "mesh_outputs.h"
#include "sampling_grid.h"
#include "frep/io/file_kind.h"
#include "frep/io/vdb_reader.h"

namespace frep::cli {

namespace {

bool hasVdbExtension(const std::string& path) {
  auto dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return false;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == "vdb";
}

// frep mesh input.vdb: the sampled values of a FloatGrid (frep sample's output) meshed in-process
// by the core's meshSamples, the same marching tetrahedra as the model mesher (docs/mesh.md).
int runMeshVdb(const MeshRequest& request) {
  if (request.region.out.empty()) throw badArgs("-O/--out: the output mesh path (.ply, .obj, .stl, .wrl, .pov, .3mf, .glb) is required");
  std::vector<MeshOutput> outputs = resolveMeshOutputs(request);
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  // The grid's extent and transform are the file's; the model options have nothing to act on.
  const std::string input = "'" + request.model.path + "' is a .vdb: its grid and transform are used as stored";
  if (!request.region.bounds.empty()) throw badArgs("-b/--bounds: " + input);
  if (request.region.res != 0 || !request.region.cells.empty()) throw badArgs("--res/-g: " + input);
  if (!request.model.params.empty()) throw badArgs("-a/--params: " + input + " (parameters were bound by frep sample)");
  if (!request.model.mapping.empty()) throw badArgs("-x/--map: " + input);
  if (request.model.iso != 0.0) throw badArgs("-i/--iso: " + input + " (sample the model with -i instead)");
  if (request.tolerance > 0 || request.noSharp)
    throw badArgs("--tolerance/--no-sharp: simplification checks every change against the model; a .vdb has none");
  if (!request.farm.listen.empty() || request.farm.expectWorkers != 0 || request.farm.resume ||
      !request.farm.curveDir.empty() || !request.farm.verify.empty() || request.farm.replicate != 1)
    throw badArgs("--listen/--expect-workers/--resume/--curve/--verify/--replicate: a .vdb is meshed in-process (use --threads)");

  openMeshOutputFiles(outputs);
  const auto start = std::chrono::steady_clock::now();
  io::SampledVdb vdb = io::readSampledVdb(request.model.path, request.model.object);
  const double readSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("meshing grid '{}' of {}: {} leaves, {}", vdb.gridName, request.model.path, vdb.samples.leaves.size(),
               vdb.transformDescription);
  SampledMeshOptions options;
  options.threads = request.threads;
  SampledMesh sm = meshSamples(vdb.samples, options);
  const size_t leaves = vdb.samples.leaves.size();
  vdb.samples = SampleResult{};  // the values are no longer needed
  Mesh& mesh = sm.mesh;
  if (vdb.toWorld) vdb.toWorld(mesh);
  const double meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - readSeconds;
  if (sm.incompleteCells)
    spdlog::warn("{} crossed cell(s) have a corner outside the active band (only its sign stored): left out, so the "
                 "mesh has holes there; sample with a band of at least 1 voxel",
                 sm.incompleteCells);
  if (mesh.triangles.empty()) spdlog::warn("grid '{}' has no sign change between active voxels: the mesh is empty", vdb.gridName);
  // The file's content hash, not its path: the mesh's bytes do not depend on how it was spelt.
  std::string comment = "frep mesh of grid '" + vdb.gridName + "' of a .vdb (content hash " + vdb.contentHash +
                        ", sampled values); normals point outward (decreasing f)";
  jsonPhase("write");
  std::array<double, 6> box{0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      if (i == 0 || mesh.positions[i][c] < box[c]) box[c] = mesh.positions[i][c];
      if (i == 0 || mesh.positions[i][c] > box[3 + c]) box[3 + c] = mesh.positions[i][c];
    }
  std::vector<std::string> wrote = writeMeshOutputs(outputs, mesh, request, vdb.gridName, comment, box,
                                                    (box[5] - box[2]) / 64);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const MeshStats& s = mesh.stats;
  std::ostream& text = request.farm.json ? std::cerr : std::cout;
  for (const auto& line : wrote) text << line << "\n";
  text << "  from grid '" << vdb.gridName << "' of " << request.model.path << ": " << leaves << " leaves, "
       << vdb.transformDescription << "\n"
       << "  cells examined " << s.cellsVisited << ", crossed " << s.cellsCrossed << ", left out " << sm.incompleteCells
       << "\n"
       << "  time " << formatNumber(std::round(readSeconds * 1000) / 1000) << " s reading, "
       << formatNumber(std::round(meshSeconds * 1000) / 1000) << " s meshing, "
       << formatNumber(std::round(seconds * 1000) / 1000) << " s in all\n";
  jsonDone(request.region.out, false);
  return kExitOk;
}

}  // namespace

int runMesh(const MeshRequest& request) {
  if (hasVdbExtension(request.model.path) || io::sniffFile(request.model.path) == io::FileKind::Vdb)
    return runMeshVdb(request);
  if (request.region.out.empty()) throw badArgs("-O/--out: the output mesh path (.ply, .obj, .stl, .wrl, .pov, .3mf, .glb) is required");
  std::vector<MeshOutput> outputs = resolveMeshOutputs(request);
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  if (request.tolerance < 0 && request.tolerance != -1)
    throw badArgs("--tolerance: expected 0 (no simplification) or more voxels, got " + formatNumber(request.tolerance));
  if (!std::isfinite(request.tolerance)) throw badArgs("--tolerance: expected a finite number of voxels");
  if (request.tolerance > 0 && !(request.tolerance >= kMinSimplifyTolerance && request.tolerance <= kMaxSimplifyTolerance))
    throw badArgs("--tolerance: expected 0 (no simplification) or 1e-30 to 1e30 voxels, got " + formatNumber(request.tolerance));
  farm::FarmOptions options = farmOptions(request.farm, request.region.out, request.logLevel, request.threads);
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 128);
  LoadedModel m = loadModel(request.model, true);
  // The master merges and simplifies the whole mesh: its blocks' vectors come and go by the
  // thousand (docs/farm.md, "The processes' allocator").
  farm::applyAllocatorPolicy();
  // A 1D or 2D object is meshed as frep sample samples it: the slab or prism it is in 3D
  // (constant along the missing axes), cut by the box.
  if (m.dims > 3)
    throw badArgs("frep mesh needs at most three coordinates; '" + m.model.objectName + "' has " +
                  std::to_string(m.dims) + " (map them with -x, e.g. -x X,Y,Z,0.5)");
  GridSpec grid = makeGrid(box, 3, res);
  // No --workers and a grid of one default brick at most: in-process (smallJobInProcess).
  const std::string inProcessRule = smallJobInProcess(request.farm, grid.dims);
  if (!inProcessRule.empty()) options.workers = 0;
  if (request.farm.brick == -1)
    options.brickVoxels = chooseBrick(grid.dims, options.workers, request.farm.listen, request.farm.expectWorkers);
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] < 2 || grid.dims[a] >= kMaxMeshGridPoints)
      throw badArgs("--res/-g: the grid needs 2 to " + std::to_string(kMaxMeshGridPoints - 1) + " points per axis");
  checkJobSize(grid, options.brickVoxels);

  // A solid cut by the box is meshed as solid ∩ box, capped on the faces that cut it (the field
  // min(f, box faces) on a grid one voxel larger on every side), unless --open-rim.
  const GridSpec userGrid = grid;
  const BoxCut cut = findBoxCut(m, grid, request.threads,
                                request.openRim ? "the mesh is open there (--open-rim)"
                                                : "the mesh is capped there (solid ∩ box); --open-rim leaves it open");
  const bool capped = cut.faces != 0 && !request.openRim;
  if (capped) {
    for (int a = 0; a < 3; ++a) {
      grid.origin[a] -= grid.voxel;
      grid.dims[a] += 2;
    }
    if (grid.dims[0] >= kMaxMeshGridPoints || grid.dims[1] >= kMaxMeshGridPoints || grid.dims[2] >= kMaxMeshGridPoints)
      throw badArgs("--res/-g: the grid needs 2 to " + std::to_string(kMaxMeshGridPoints - 3) +
                    " points per axis when the box cuts the solid");
    checkJobSize(grid, options.brickVoxels);
  }

  openMeshOutputFiles(outputs);
  io::AtomicOutput reportOut("-O/--out (report)", request.region.out + ".report.json");
  // Adaptive simplification: each worker does the blocks inside its brick, the master the rest
  // (deterministic, so the file still does not depend on the split; docs/mesh.md).
  // Not by default for models with extremum nodes: every check would run searches.
  farm::JobSpec job = makeJob(m, request.model.path, grid, "mesh");
  // The caps lie 2e-3 voxel inside the box's faces: the roots on the edges that leave the box
  // then fall inside the edges (not on the faces' grid points, where endGuard would push them
  // out), so every vertex lies in the box.
  const double capInset = 2e-3 * userGrid.voxel;
  if (capped) {
    std::array<double, 3> lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = userGrid.origin[a] + capInset;
      hi[a] = userGrid.origin[a] + userGrid.voxel * (userGrid.dims[a] - 1) - capInset;
    }
    setCutBox(job, lo, hi);
  }
  TapePtr tape = farm::compileJobModel(job);  // the workers' field, capped or not
  SimplifyOptions so;
  so.tolerance = request.tolerance >= 0 ? request.tolerance : tape->hasExtrema() ? 0.0 : 0.1;
  so.sharpFeatures = !request.noSharp;
  so.threads = request.threads;  // the master's passes (the workers' follow --threads too)
  so.bricksSimplified = so.tolerance > 0 ? options.brickVoxels : 0;
  if (request.tolerance < 0 && tape->hasExtrema())
    spdlog::info("the model has extremum nodes: not simplified (each check would run a search); give --tolerance to");
  job.mutable_mesh()->set_tolerance(so.tolerance);
  job.mutable_mesh()->set_no_sharp(!so.sharpFeatures);
  spdlog::info("meshing '{}' on {}x{}x{} points of {}", m.model.objectName, grid.dims[0], grid.dims[1], grid.dims[2],
               grid.voxel);
  const auto start = std::chrono::steady_clock::now();
  if (!inProcessRule.empty()) spdlog::info("{}", inProcessRule);
  jsonPhase("compute");
  farm::FarmOutcome outcome = runFarmJob(job, options);
  farm::FarmReport& report = outcome.report;
  report.inProcessRule = inProcessRule;
  requireComplete(reportOut, report, request.farm.strict);
  Mesh& mesh = outcome.mesh;
  const double meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (so.tolerance > 0)
    spdlog::info("simplifying across the bricks: {} triangles (tolerance {} voxel, sharp features {}); a signal "
                 "now ends the run, --resume then redoes only this step",
                 mesh.triangles.size(), so.tolerance, so.sharpFeatures ? "on" : "off");
  if (so.tolerance > 0) jsonPhase("simplify");
  so.progress = farm::simplifyProgress(options.progressBar, options.progressJson);
  // The bound of the whole pipeline: the mesher's chords and roots (searches included), then
  // what the simplification certified for the triangles it made (docs/mesh.md, "Error bound").
  const double rawBound = rawMeshErrorBound(mesh, *tape, grid);
  SimplifyStats ss = simplifyMesh(mesh, tape, grid, so);
  report.surfaceErrorBound = std::max(rawBound, so.tolerance > 0 ? ss.errorBound : 0.0);
  report.simplifyTolerance = so.tolerance;
  report.sharpFeatures = so.sharpFeatures;
  report.simplify = ss;
  // Every mesh written is closed and oriented: checked here, after the merge and the
  // simplification, so a fault anywhere in the pipeline is an error, never a silent file.
  uint64_t unpaired = 0;
  const std::string defect = closureDefect(mesh.triangles, mesh.positions.size(), &unpaired);
  if (!defect.empty() && (capped || cut.faces == 0)) {  // --open-rim: open where the box cuts, by request
    writeReport(reportOut, report);
    throw CliError(kExitOpenMesh, "internal error: the merged mesh is not closed (" + std::to_string(unpaired) +
                                      " unpaired directed edges; first: " + defect +
                                      "); nothing written. Please report it with the command line");
  }
  report.vertices = mesh.positions.size();
  report.cutFaces = cut.names();
  report.capped = capped;
  report.triangles = mesh.triangles.size();
  const double simplifySeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - meshSeconds;
  // Provenance as frep sample's: the model's hash and the resolved options, never the path.
  char modelHash[17];
  std::snprintf(modelHash, sizeof modelHash, "%016llx", static_cast<unsigned long long>(m.model.sourceHash));
  std::string comment = "frep mesh of '" + m.model.objectName + "', grid " + std::to_string(grid.dims[0]) + "x" +
                        std::to_string(grid.dims[1]) + "x" + std::to_string(grid.dims[2]) + " voxel " +
                        formatNumber(grid.voxel) + "; normals point outward (decreasing f); model hash " + modelHash +
                        ", " + canonicalModel(m);
  jsonPhase("write");
  // Colours after the merge and the simplification, at the final vertices half a voxel inside:
  // the same for any split of the job (colour.h).
  const bool coloured = !m.colour.empty() && wantsColours(outputs);
  if (coloured) colourMesh(mesh, ColourField(m.colour, 3), 0.5 * grid.voxel, request.threads);
  const std::array<double, 6> extent{userGrid.origin[0],
                                  userGrid.origin[1],
                                  userGrid.origin[2],
                                  userGrid.origin[0] + userGrid.voxel * (userGrid.dims[0] - 1),
                                  userGrid.origin[1] + userGrid.voxel * (userGrid.dims[1] - 1),
                                  userGrid.origin[2] + userGrid.voxel * (userGrid.dims[2] - 1)};
  std::vector<std::string> wrote;
  writeReportWith(reportOut, report, [&] {
    wrote = writeMeshOutputs(outputs, mesh, request, m.model.objectName, comment, extent, grid.voxel);
    std::vector<std::string> paths;
    for (const MeshOutput& o : outputs) paths.push_back(o.path);
    return paths;
  });
  std::remove(options.journalPath.c_str());  // the output is complete: nothing to resume
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const MeshStats& s = mesh.stats;
  const double dense = double(grid.dims[0] - 1) * double(grid.dims[1] - 1) * double(grid.dims[2] - 1);
  std::ostream& text = request.farm.json ? std::cerr : std::cout;
  for (const auto& line : wrote) text << line << "\n";
  if (coloured) text << "  colours: s[1..3] of '" << m.model.objectName << "' half a voxel inside every vertex\n";
  text << "  grid " << grid.dims[0] << "x" << grid.dims[1] << "x" << grid.dims[2] << " points of "
       << formatNumber(grid.voxel) << ", cells examined " << s.cellsVisited << " ("
       << formatNumber(std::round(1e4 * double(s.cellsVisited) / dense) / 100) << "% of " << uint64_t(dense)
       << "), crossed " << s.cellsCrossed << "\n"
       << (so.tolerance > 0 ? "  simplified from " + std::to_string(ss.trianglesBefore) + " triangles (tolerance " +
                                  formatNumber(so.tolerance) + " voxel, sharp features " +
                                  (so.sharpFeatures ? "on" : "off") + "): error bound " +
                                  formatNumber(ss.errorBound) + ", " + formatNumber(std::round(simplifySeconds * 1000) / 1000) + " s\n"
                            : std::string())
       << "  evaluations: grid points " << s.samplePointEvals << ", root finding " << s.rootEvals << ", gradients "
       << s.gradientEvals << "\n"
       << "  NaN values " << report.nanValues << (report.nanValues ? " (domain errors, taken as outside)" : "")
       << ", domain errors " << report.domainErrors.total()
       << (report.domainErrors.total()
               ? " (" + report.domainErrors.describe() + "; documented values used, see docs/language.md)"
               : "")
       << "\n"
       << "  time " << formatNumber(std::round(meshSeconds * 1000) / 1000) << " s meshing, "
       << formatNumber(std::round(seconds * 1000) / 1000) << " s in all\n"
       << "  " << bricksSummary(report) << "\n"
       << "  report " << request.region.out << ".report.json\n";
  jsonDone(request.region.out, true);
  return kExitOk;
}

}  // namespace frep::cli
