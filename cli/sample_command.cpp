// frep sample: the core sampler's narrow band, written as an OpenVDB level set.
#include <spdlog/spdlog.h>

#include <cmath>
#include <iostream>

#include "arg_parse.h"
#include "atomic_output.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/sample.h"
#include "frep/tape.h"
#include "sampling_grid.h"
#include "vdb_writer.h"

namespace frep::cli {

int runSample(const SampleRequest& request) {
  if (request.region.out.empty()) throw badArgs("-O/--out: the output .vdb path is required");
  if (request.band < 1 || request.band > 64)
    throw badArgs("--band: expected an integer from 1 to 64 (voxels), got " + std::to_string(request.band));
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 128);
  LoadedModel m = loadModel(request.model, true);
  GridSpec grid = makeGrid(box, 3, res);

  AtomicOutput out("-O/--out", request.region.out);
  TapePtr tape = Tape::compile(m.field, 3);
  frep::SampleOptions options;
  options.bandVoxels = request.band;
  options.threads = request.threads;
  spdlog::info("sampling '{}' on {}x{}x{} voxels of {}", m.model.objectName, grid.dims[0], grid.dims[1],
               grid.dims[2], grid.voxel);
  SampleResult result = frep::sample(tape, grid, options);

  VdbMetadata meta;
  meta.gridName = m.model.objectName;
  meta.commandLine = request.commandLine;
  meta.params = request.model.params;
  meta.sourceHash = m.model.sourceHash;
  meta.iso = request.model.iso;
  writeLevelSet(out.tempPath(), result, meta);
  out.commit();

  const SampleStats& s = result.stats;
  const double fraction = s.denseEvals ? double(s.pointEvals) / double(s.denseEvals) : 0.0;
  std::cout << "wrote " << request.region.out << ": " << grid.dims[0] << "x" << grid.dims[1] << "x" << grid.dims[2]
            << " voxels of " << formatNumber(grid.voxel) << ", band " << request.band << " voxels\n"
            << "  leaves " << result.leaves.size() << ", tiles " << result.tiles.size() << "\n"
            << "  evaluations " << s.pointEvals << " (" << formatNumber(std::round(fraction * 1e4) / 100)
            << "% of dense " << s.denseEvals << "), interval " << s.intervalEvals << "\n"
            << "  NaN values " << s.nanValues << (s.nanValues ? " (domain errors, stored as outside)" : "") << "\n";
  return kExitOk;
}

}  // namespace frep::cli
