#include "farm_job.h"

#include <unistd.h>

#include <cmath>
#include <algorithm>
#include <fstream>
#include <thread>

#include "arg_parse.h"
#include "brick.h"
#include "exit_codes.h"

namespace frep::cli {

farm::JobSpec makeJob(const LoadedModel& m, const std::string& modelPath, const GridSpec& grid,
                      const std::string& operation) {
  farm::JobSpec job;
  job.set_operation(operation);
  job.set_model_source(m.source);
  job.set_model_name(modelPath);
  job.set_object(m.model.objectName);
  for (double p : m.spec.params) job.add_params(p);
  for (int a : m.spec.axis) job.add_map_axis(a);
  for (double c : m.spec.constant) job.add_map_constant(c);
  job.set_iso(m.spec.iso);
  farm::setGrid(job, grid);
  return job;
}

farm::FarmOptions farmOptions(const FarmRequest& f, const std::string& out, const std::string& logLevel, int threads) {
  if (f.workers < -1) throw badArgs("--workers: expected 0 (in-process) or more, got " + std::to_string(f.workers));
  if (f.brick != -1 && (f.brick < 8 || f.brick % 8 != 0))
    throw badArgs("--brick: expected a positive multiple of 8 voxels, got " + std::to_string(f.brick));
  if (f.heartbeatMs < 10) throw badArgs("--heartbeat-ms: expected at least 10, got " + std::to_string(f.heartbeatMs));
  if (!f.listen.empty() && f.listen.rfind("tcp://", 0) != 0)
    throw badArgs("--listen: expected tcp://HOST:PORT (e.g. tcp://*:5555), got '" + f.listen + "'");
  if (f.expectWorkers < 0)
    throw badArgs("--expect-workers: expected 0 or more, got " + std::to_string(f.expectWorkers));
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
  o.journalPath = out + ".journal";
  o.logLevel = logLevel == "info" ? "warn" : logLevel;
  o.threads = threads;
  return o;
}

int chooseBrick(const std::array<int32_t, 3>& dims, int workers, const std::string& listen, int expectWorkers) {
  int n = !listen.empty() ? expectWorkers
          : workers < 0   ? int(std::max(1u, std::thread::hardware_concurrency()))
                          : workers;
  if (n <= 0) return 64;  // in-process, or a cluster of unknown size: the default brick
  int brick = 64;
  auto bricks = [&](int e) {
    int64_t count = 1;
    for (int32_t d : dims) count *= (d + e - 1) / e;
    return count;
  };
  // Two bricks per worker at least, so that none idles and a slow one can be backed up; not
  // below 16 voxels, where a brick's fixed costs (messages, interval pass) start to dominate.
  while (brick > 16 && bricks(brick) < 2 * int64_t(n)) brick /= 2;
  return brick;
}

farm::FarmOutcome runFarmJob(const farm::JobSpec& job, const farm::FarmOptions& options) {
  try {
    return farm::runJob(job, options);
  } catch (const std::invalid_argument& e) {
    throw badArgs(e.what());
  } catch (const std::runtime_error& e) {
    throw CliError(kExitFarmError, e.what());
  }
}

void writeReport(AtomicOutput& reportOut, const farm::FarmReport& report) {
  {
    farm::FarmReport final = report;
    final.peakRssBytes = farm::peakRssBytes();  // after the output was written
    std::ofstream r(reportOut.tempPath());
    r << final.toJson() << "\n";
    if (!r) throw ioError("cannot write " + reportOut.tempPath());
  }
  reportOut.commit();
}

namespace {
std::string poisonedMessage(const farm::FarmReport& report) {
  std::string s = std::to_string(report.poisoned.size()) + " brick(s) failed " + "3 times and were given up:";
  for (auto& p : report.poisoned)
    s += "\n  brick " + std::to_string(p.brick) + " voxels [" + std::to_string(p.lo[0]) + "," +
         std::to_string(p.lo[1]) + "," + std::to_string(p.lo[2]) + ")-(" + std::to_string(p.hi[0]) + "," +
         std::to_string(p.hi[1]) + "," + std::to_string(p.hi[2]) + "): " + p.error;
  return s + "\nthe other bricks are in the journal; fix the cause and run again with --resume";
}
}  // namespace

void requireComplete(AtomicOutput& reportOut, const farm::FarmReport& report) {
  if (!report.interrupted && report.poisoned.empty()) return;
  writeReport(reportOut, report);
  if (report.interrupted)
    throw CliError(kExitInterrupted, "stopped by a signal; " +
                                         std::to_string(report.bricksComputed + report.bricksFromJournal) + " of " +
                                         std::to_string(report.bricks) +
                                         " bricks are in the journal: run the same command with --resume");
  throw CliError(kExitPoisoned, poisonedMessage(report));
}

std::string bricksSummary(const farm::FarmReport& report) {
  return "bricks " + std::to_string(report.bricks) + " (" + std::to_string(report.bricksComputed) + " computed, " +
         std::to_string(report.bricksFromJournal) + " from the journal), workers " +
         std::to_string(report.workersSeen) + ", retries " + std::to_string(report.retries) + ", " +
         formatNumber(std::round(report.wallSeconds * 1000) / 1000) + " s";
}

}  // namespace frep::cli
