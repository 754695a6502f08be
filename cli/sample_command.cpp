// frep sample: the model's narrow band, computed brick by brick on the farm (or in-process
// with --workers 0), merged and written as an OpenVDB level set with a JSON report beside it.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>

#include "frep/farm/allocator_tuning.h"
#include "arg_parse.h"
#include "frep/farm/job.h"
#include "frep/io/world_lattice.h"
#include "frep/io/atomic_output.h"
#include "commands.h"
#include "frep/net/curve.h"
#include "exit_codes.h"
#include "farm_job.h"
#include "json_events.h"
#include "frep/master/farm_master.h"
#include "sampling_grid.h"
#include "frep/io/vdb_writer.h"
#include "frep/sampling/band_distance.h"
#include "frep/sampling/exact_band_distance.h"

namespace frep::cli {
namespace {

std::string exact(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The job as resolved (canonicalModel, then the world lattice, band and store):
// the same text however the command was spelt (argv[0], the model's path, option order, -g or
// --res for the same lattice), so the file's bytes do not depend on the spelling.
std::string jobDescription(const LoadedModel& m, const GridSpec& g, int band, const std::string& store) {
  std::string s = "sample " + canonicalModel(m) + " voxel=" + exact(g.voxel) + " lattice=";
  for (int a = 0; a < 3; ++a) s += (a ? "," : "") + std::to_string(std::llround(g.origin[a] / g.voxel));
  s += ":";
  for (int a = 0; a < 3; ++a) s += (a ? "," : "") + std::to_string(std::llround(g.origin[a] / g.voxel) + g.dims[a] - 1);
  return s + " band=" + std::to_string(band) + " store=" + store;
}

}  // namespace

int runSample(const SampleRequest& request) {
  if (request.region.out.empty()) throw badArgs("-O/--out: the output .vdb path is required");
  if (request.band < 1 || request.band > 64)
    throw badArgs("--band: expected an integer from 1 to 64 (voxels), got " + std::to_string(request.band));
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 128);
  farm::FarmOptions options = farmOptions(request.farm, request.region.out, request.logLevel, request.threads);
  GridSpec grid = makeWorldLatticeGrid(box, res);
  // No --workers and a grid of one default brick at most: in-process (smallJobInProcess).
  const std::string inProcessRule = smallJobInProcess(request.farm, grid.dims);
  if (!inProcessRule.empty()) options.workers = 0;
  if (request.farm.brick == -1)
    options.brickVoxels = chooseBrick(grid.dims, options.workers, request.farm.listen, request.farm.expectWorkers);
  checkJobSize(grid, options.brickVoxels);  // before the model is even read: refused at once
  LoadedModel m = loadModel(request.model, true);
  // The master receives, journals, decodes and streams every brick: its buffers come and go by
  // the brick (farm::applyAllocatorPolicy, docs/farm.md "The processes' allocator").
  farm::applyAllocatorPolicy();

  io::AtomicOutput out("-O/--out", request.region.out);
  io::AtomicOutput reportOut("-O/--out (report)", request.region.out + ".report.json");
  // A solid cut by the box is sampled as solid ∩ box: the field min(f, the box's faces) on the
  // lattice grown by the band (and a voxel) on every side, so the level set closes on the faces.
  const BoxCut cut = findBoxCut(m, grid, request.threads,
                                "the level set is that of solid ∩ box, closed on those faces");
  std::array<double, 3> cutLo{}, cutHi{};
  if (cut.faces) {
    Box grown = box;
    const double margin = (request.band + 1) * grid.voxel;  // band + 1 lattice points more (rounded outward)
    for (int a = 0; a < 3; ++a) {
      cutLo[a] = grid.origin[a];
      cutHi[a] = grid.origin[a] + grid.voxel * (grid.dims[a] - 1);
      grown.lo[a] = cutLo[a] - margin;
      grown.hi[a] = cutHi[a] + margin;
    }
    grid = io::worldLatticeGrid("-b/--bounds", grown.lo, grown.hi, grid.voxel);
  }
  grid = io::leafAlignedGrid(grid);  // after the cut box: the cut stays the requested box's
  checkJobSize(grid, options.brickVoxels);  // the grid as sampled: grown by the cut, then aligned
  farm::JobSpec job = makeJob(m, request.model.path, grid, "sample");
  job.set_band(request.band);
  // The workers store the band's distance: the estimate (--store sdf, fog) or the exact distance
  // to the samples' piecewise-linear zero set (sdf-exact); the master merges either as it is.
  job.set_distance(request.store != "raw");
  job.set_distance_exact(request.store == "sdf-exact");
  if (cut.faces) setCutBox(job, cutLo, cutHi);
  spdlog::info("sampling '{}' on {}x{}x{} voxels of {}", m.model.objectName, grid.dims[0], grid.dims[1],
               grid.dims[2], grid.voxel);
  // The merge streams into the grid slab by slab as the slabs complete (the master never holds
  // the whole sample and the tree at once); a job that does not complete writes nothing (what it
  // streamed is dropped with the builder). With --verify, a worker convicted of forging after its
  // bricks were streamed restarts the stream (a new builder; the master merges from the journal).
  std::optional<io::LevelSetBuilder> builder;
  // raw and sdf write the leaves' values as they are: the finished leaves go to a temporary file.
  const bool spill = request.store != "fog";
  builder.emplace(farm::gridOf(job), request.band, spill);  // the lattice the master merges on
  options.sampleSink.tiles = [&](const std::vector<Tile>& tiles) { builder->addTiles(tiles); };
  options.sampleSink.leaves = [&](const std::vector<LeafBlock>& slab) { builder->addLeaves(slab); };
  options.sampleSink.restart = [&] {
    builder.reset();  // its memory first
    builder.emplace(farm::gridOf(job), request.band, spill);
  };
  if (!inProcessRule.empty()) spdlog::info("{}", inProcessRule);
  jsonPhase("compute");
  farm::FarmOutcome outcome = runFarmJob(job, options);
  farm::FarmReport& report = outcome.report;
  report.inProcessRule = inProcessRule;
  requireComplete(reportOut, report, request.farm.strict);
  report.cutFaces = cut.names();
  if (job.distance())
    report.errorBounds.push_back("stored value (signed distance): " +
                                 (job.distance_exact() ? exactBandDistanceBound() : bandDistanceBound()));

  io::VdbMetadata meta;
  meta.gridName = m.model.objectName;
  meta.job = jobDescription(m, grid, request.band, request.store);
  meta.source = baseName(request.model.path);
  meta.store = request.store == "raw"   ? io::VdbStore::Raw
               : request.store == "fog" ? io::VdbStore::Fog
                                        : io::VdbStore::Sdf;  // sdf, sdf-exact
  meta.params = request.model.params;
  meta.sourceHash = m.model.sourceHash;
  meta.iso = request.model.iso;
  meta.distanceValues = job.distance();
  meta.exactDistance = job.distance_exact();
  jsonPhase("write");
  builder->write(out.tempPath(), meta);
  writeReportWith(reportOut, report, [&] {
    out.commit();
    return std::vector<std::string>{out.path()};
  });
  std::remove(options.journalPath.c_str());  // the output is complete: nothing to resume

  const SampleStats& s = outcome.result.stats;
  const double fraction = s.denseEvals ? double(s.pointEvals) / double(s.denseEvals) : 0.0;
  std::ostream& text = request.farm.json ? std::cerr : std::cout;
  text << "wrote " << request.region.out << ": " << grid.dims[0] << "x" << grid.dims[1] << "x" << grid.dims[2]
       << " voxels of " << formatNumber(grid.voxel) << ", band " << request.band << " voxels\n"
       << "  leaves " << builder->leaves() << ", tiles " << outcome.result.tiles.size() << "\n"
       << "  evaluations " << s.pointEvals << " (" << formatNumber(std::round(fraction * 1e4) / 100)
       << "% of dense " << s.denseEvals << "), interval " << s.intervalEvals << "\n"
       << "  NaN values " << s.nanValues << (s.nanValues ? " (domain errors, stored as outside)" : "") << "\n"
       << "  domain errors " << s.domainErrors.total()
       << (s.domainErrors.total() ? " (" + s.domainErrors.describe() + "; documented values used, see docs/language.md)" : "")
       << "\n"
       << "  " << bricksSummary(report) << "\n"
       << "  report " << request.region.out << ".report.json\n";
  jsonDone(request.region.out, true);
  return kExitOk;
}

int runKeygen(const std::string& dir, bool force) {
  try {
    farm::generateCurveKeys(dir, force);
  } catch (const farm::CurveKeysExist& e) {
    throw badArgs(std::string("keygen: ") + e.what());  // exit 2: nothing written
  } catch (const std::exception& e) {
    throw ioError(std::string("keygen: ") + e.what());
  }
  std::cout << "wrote CURVE keys to " << dir << ": master.pub, master.key (keep on the master), worker.pub, "
            << "worker.key (copy to workers with master.pub), authorized (worker keys the master admits)\n";
  return kExitOk;
}

}  // namespace frep::cli
