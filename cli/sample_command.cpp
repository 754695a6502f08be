// frep sample: the model's narrow band, computed brick by brick on the farm (or in-process
// with --workers 0), merged and written as an OpenVDB level set with a JSON report beside it.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iostream>

#include "arg_parse.h"
#include "atomic_output.h"
#include "commands.h"
#include "curve.h"
#include "exit_codes.h"
#include "farm_master.h"
#include "sampling_grid.h"
#include "vdb_writer.h"

namespace frep::cli {

namespace {

farm::JobSpec makeJob(const LoadedModel& m, const std::string& path, const GridSpec& grid, int band) {
  farm::JobSpec job;
  job.set_operation("sample");
  job.set_model_source(m.source);
  job.set_model_name(path);
  job.set_object(m.model.objectName);
  for (double p : m.spec.params) job.add_params(p);
  for (int a : m.spec.axis) job.add_map_axis(a);
  for (double c : m.spec.constant) job.add_map_constant(c);
  job.set_iso(m.spec.iso);
  for (int a = 0; a < 3; ++a) {
    job.add_origin(grid.origin[a]);
    job.add_dims(grid.dims[a]);
  }
  job.set_voxel(grid.voxel);
  job.set_band(band);
  return job;
}

farm::FarmOptions farmOptions(const SampleRequest& r) {
  const FarmRequest& f = r.farm;
  if (f.workers < -1) throw badArgs("--workers: expected 0 (in-process) or more, got " + std::to_string(f.workers));
  if (f.brick < 8 || f.brick % 8 != 0)
    throw badArgs("--brick: expected a positive multiple of 8 voxels, got " + std::to_string(f.brick));
  if (f.heartbeatMs < 10) throw badArgs("--heartbeat-ms: expected at least 10, got " + std::to_string(f.heartbeatMs));
  if (!f.listen.empty() && f.listen.rfind("tcp://", 0) != 0)
    throw badArgs("--listen: expected tcp://HOST:PORT (e.g. tcp://*:5555), got '" + f.listen + "'");
  farm::FarmOptions o;
  o.workers = f.workers;
  o.listen = f.listen;
  o.expectWorkers = f.expectWorkers;
  o.brickVoxels = f.brick;
  o.heartbeatMs = f.heartbeatMs;
  o.curveDir = f.curveDir;
  o.resume = f.resume;
  o.progressJson = f.json;
  o.progressBar = !f.json && !f.noProgress && ::isatty(2);
  o.journalPath = r.region.out + ".journal";
  o.logLevel = r.logLevel == "info" ? "warn" : r.logLevel;
  return o;
}

std::string poisonedMessage(const farm::FarmReport& report) {
  std::string s = std::to_string(report.poisoned.size()) + " brick(s) failed " + "3 times and were given up:";
  for (auto& p : report.poisoned)
    s += "\n  brick " + std::to_string(p.brick) + " voxels [" + std::to_string(p.lo[0]) + "," +
         std::to_string(p.lo[1]) + "," + std::to_string(p.lo[2]) + ")-(" + std::to_string(p.hi[0]) + "," +
         std::to_string(p.hi[1]) + "," + std::to_string(p.hi[2]) + "): " + p.error;
  return s + "\nthe other bricks are in the journal; fix the cause and run again with --resume";
}

}  // namespace

int runSample(const SampleRequest& request) {
  if (request.region.out.empty()) throw badArgs("-O/--out: the output .vdb path is required");
  if (request.band < 1 || request.band > 64)
    throw badArgs("--band: expected an integer from 1 to 64 (voxels), got " + std::to_string(request.band));
  if (request.threads < 0) throw badArgs("--threads: expected 0 (all cores) or more, got " + std::to_string(request.threads));
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 128);
  farm::FarmOptions options = farmOptions(request);
  LoadedModel m = loadModel(request.model, true);
  GridSpec grid = makeGrid(box, 3, res);

  AtomicOutput out("-O/--out", request.region.out);
  AtomicOutput reportOut("-O/--out (report)", request.region.out + ".report.json");
  farm::JobSpec job = makeJob(m, request.model.path, grid, request.band);
  spdlog::info("sampling '{}' on {}x{}x{} voxels of {}", m.model.objectName, grid.dims[0], grid.dims[1],
               grid.dims[2], grid.voxel);
  farm::FarmOutcome outcome;
  try {
    outcome = farm::runSampleJob(job, options);
  } catch (const std::invalid_argument& e) {
    throw badArgs(e.what());
  } catch (const std::runtime_error& e) {
    throw CliError(kExitFarmError, e.what());
  }
  const farm::FarmReport& report = outcome.report;
  auto writeReport = [&] {
    {
      std::ofstream r(reportOut.tempPath());
      r << report.toJson() << "\n";
      if (!r) throw ioError("cannot write " + reportOut.tempPath());
    }
    reportOut.commit();
  };
  if (report.interrupted || !report.poisoned.empty()) writeReport();
  if (report.interrupted)
    throw CliError(kExitInterrupted, "stopped by a signal; " + std::to_string(report.bricksComputed + report.bricksFromJournal) +
                                         " of " + std::to_string(report.bricks) +
                                         " bricks are in the journal: run the same command with --resume");
  if (!report.poisoned.empty()) throw CliError(kExitPoisoned, poisonedMessage(report));

  VdbMetadata meta;
  meta.gridName = m.model.objectName;
  meta.commandLine = request.commandLine;
  meta.params = request.model.params;
  meta.sourceHash = m.model.sourceHash;
  meta.iso = request.model.iso;
  writeLevelSet(out.tempPath(), outcome.result, meta);
  out.commit();
  writeReport();
  std::remove(options.journalPath.c_str());  // the output is complete: nothing to resume

  const SampleStats& s = outcome.result.stats;
  const double fraction = s.denseEvals ? double(s.pointEvals) / double(s.denseEvals) : 0.0;
  std::ostream& text = request.farm.json ? std::cerr : std::cout;
  text << "wrote " << request.region.out << ": " << grid.dims[0] << "x" << grid.dims[1] << "x" << grid.dims[2]
       << " voxels of " << formatNumber(grid.voxel) << ", band " << request.band << " voxels\n"
       << "  leaves " << outcome.result.leaves.size() << ", tiles " << outcome.result.tiles.size() << "\n"
       << "  evaluations " << s.pointEvals << " (" << formatNumber(std::round(fraction * 1e4) / 100)
       << "% of dense " << s.denseEvals << "), interval " << s.intervalEvals << "\n"
       << "  NaN values " << s.nanValues << (s.nanValues ? " (domain errors, stored as outside)" : "") << "\n"
       << "  domain errors " << s.domainErrors.total()
       << (s.domainErrors.total() ? " (" + s.domainErrors.describe() + "; documented values used, see docs/language.md)" : "")
       << "\n"
       << "  bricks " << report.bricks << " (" << report.bricksComputed << " computed, " << report.bricksFromJournal
       << " from the journal), workers " << report.workersSeen << ", retries " << report.retries << ", "
       << formatNumber(std::round(report.wallSeconds * 1000) / 1000) << " s\n"
       << "  report " << request.region.out << ".report.json\n";
  if (request.farm.json) {
    std::cout << "{\"event\":\"done\",\"output\":\"" << request.region.out << "\",\"report\":\"" << request.region.out
              << ".report.json\"}\n";
  }
  return kExitOk;
}

int runKeygen(const std::string& dir) {
  try {
    farm::generateCurveKeys(dir);
  } catch (const std::exception& e) {
    throw ioError(std::string("keygen: ") + e.what());
  }
  std::cout << "wrote CURVE keys to " << dir << ": master.pub, master.key (keep on the master), worker.pub, "
            << "worker.key (copy to workers with master.pub), authorized (worker keys the master admits)\n";
  return kExitOk;
}

}  // namespace frep::cli
