#include "farm_job.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <bitset>
#include <fstream>
#include <thread>
#include <spdlog/spdlog.h>
#include <zmq.hpp>

#include "arg_parse.h"
#include "frep/farm/job.h"
#include "exit_codes.h"
#include "frep/master/journal.h"
#include "frep/worker/job_model.h"

namespace frep::cli {

farm::JobSpec makeJob(const LoadedModel& m, const std::string& modelPath, const GridSpec& grid,
                      const std::string& operation) {
  farm::JobSpec job;
  job.set_operation(operation);
  job.set_model_source(m.source);
  job.set_model_name(modelPath);
  for (const auto& [path, contents] : m.files) {
    farm::ModelFile* f = job.add_model_files();
    f->set_path(path);
    f->set_contents(contents);
    f->set_hash(farm::modelFileHash(contents));
  }
  job.set_object(m.model.objectName);
  for (double p : m.spec.params) job.add_params(p);
  for (int a : m.spec.axis) job.add_map_axis(a);
  for (double c : m.spec.constant) job.add_map_constant(c);
  job.set_iso(m.spec.iso);
  farm::setGrid(job, grid);
  // The job's bytes are the ones m was compiled from: an in-process run need not compile it again.
  farm::rememberCompiledModel(job, m.model);
  return job;
}

namespace {

void requireRange(const char* option, long value, long lo, long hi, const std::string& what = "") {
  if (value < lo || value > hi)
    throw badArgs(std::string(option) + ": expected an integer from " + std::to_string(lo) + " to " +
                  std::to_string(hi) + what + ", got " + std::to_string(value));
}

// tcp://HOST:PORT with PORT 1..65535 (or * for any), HOST * or a name/address; then a trial bind
// (released at once), so that a bad endpoint fails now and not after the model is planned.
void checkListen(const std::string& ep) {
  const std::string usage = "--listen: expected tcp://HOST:PORT (e.g. tcp://*:5555), got '" + ep + "'";
  if (ep.rfind("tcp://", 0) != 0) throw badArgs(usage);
  const size_t colon = ep.rfind(':');
  const std::string host = ep.substr(6, colon == std::string::npos || colon < 6 ? 0 : colon - 6);
  const std::string port = colon == std::string::npos || colon < 6 ? "" : ep.substr(colon + 1);
  bool portOk = port == "*" || (!port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos &&
                                std::stol(port) >= 1 && std::stol(port) <= 65535);
  if (host.empty() || host.find_first_of(" \t/") != std::string::npos || !portOk)
    throw badArgs(usage + " (HOST is * or an address, PORT 1 to 65535)");
  try {
    zmq::context_t ctx(1);
    zmq::socket_t probe(ctx, zmq::socket_type::router);
    probe.set(zmq::sockopt::linger, 0);
    probe.bind(ep);
  } catch (const zmq::error_t& e) {
    if (e.num() == EADDRINUSE || e.num() == EACCES)
      throw CliError(kExitFarmError, "--listen: cannot bind '" + ep + "': " + e.what());
    throw badArgs(usage + ": " + e.what());
  }
}

}  // namespace

void checkJobSize(const GridSpec& grid, int brick) {
  uint64_t bricks = 1, voxels = 1;
  for (int a = 0; a < 3; ++a) {
    bricks *= uint64_t(grid.dims[a] + brick - 1) / uint64_t(brick);
    voxels *= uint64_t(grid.dims[a]);
  }
  if (bricks <= kMaxBricks) return;
  char dense[32];
  std::snprintf(dense, sizeof dense, "%.3g", double(voxels));
  throw badArgs("--res/-g/--brick: the grid of " + std::to_string(grid.dims[0]) + "x" + std::to_string(grid.dims[1]) +
                "x" + std::to_string(grid.dims[2]) + " points (" + dense + " voxels) in bricks of " +
                std::to_string(brick) + "^3 makes " + std::to_string(bricks) + " bricks (~" +
                std::to_string(bricks * kPlannedBytesPerBrick >> 20) + " MiB to plan before any work); the farm plans at most " +
                std::to_string(kMaxBricks) + ": use a larger --brick (up to " + std::to_string(kMaxBrick) +
                ") or a smaller --res/-g");
}

farm::FarmOptions farmOptions(const FarmRequest& f, const std::string& out, const std::string& logLevel, int threads) {
  requireRange("--workers", f.workers, -1, kMaxProcesses, " (0: in-process)");
  if (f.brick != -1 && (f.brick < 8 || f.brick > kMaxBrick || f.brick % 8 != 0))  // -1: not given (chooseBrick)
    throw badArgs("--brick: expected a multiple of 8 voxels from 8 to " + std::to_string(kMaxBrick) + ", got " +
                  std::to_string(f.brick));
  requireRange("--heartbeat-ms", f.heartbeatMs, 10, 600000);
  requireRange("--expect-workers", f.expectWorkers, 0, kMaxProcesses);
  requireRange("--threads", threads, 0, kMaxProcesses, " (0: all cores)");
  if (!f.listen.empty()) checkListen(f.listen);
  if (!f.listen.empty() && f.curveDir.empty() && !f.insecure && !farm::isLoopbackEndpoint(f.listen))
    throw badArgs("--listen " + f.listen +
                  ": without --curve anyone who can reach this address can join the farm and forge results; add "
                  "--curve DIR (see frep keygen) or, on a trusted network, --insecure");
  requireRange("--replicate", f.replicate, 1, 2, " (2: every brick computed by two workers, as --verify 1)");
  double verify = -1;
  if (!f.verify.empty()) {
    char* end = nullptr;
    verify = std::strtod(f.verify.c_str(), &end);
    if (end == f.verify.c_str() || *end != '\0' || !(verify >= 0 && verify <= 1))  // NaN fails too
      throw badArgs("--verify: expected the fraction of bricks to check, a number from 0 to 1, got '" + f.verify + "'");
  }
  if (f.replicate == 2 && verify >= 0 && verify != 1)
    throw badArgs("--replicate 2 checks every brick (it is --verify 1), but --verify " + f.verify + " was given too");
  farm::FarmOptions o;
  o.verifyFraction = f.replicate == 2 ? 1.0 : verify;
  o.workers = f.workers;
  o.listen = f.listen;
  o.expectWorkers = f.expectWorkers;
  o.brickVoxels = f.brick;
  o.heartbeatMs = f.heartbeatMs;
  o.curveDir = f.curveDir;
  o.insecure = f.insecure;
  o.resume = f.resume;
  o.progressJson = f.json;
  o.progressBar = !f.json && !f.noProgress && ::isatty(2);
  o.journalPath = out + ".journal";
  o.logLevel = logLevel == "info" ? "warn" : logLevel;
  o.threads = threads;
  return o;
}

std::string smallJobInProcess(const FarmRequest& f, const std::array<int32_t, 3>& dims) {
  if (f.workers != -1 || !f.listen.empty() || f.expectWorkers != 0 || !f.verify.empty() || f.replicate != 1) return "";
  const uint64_t points = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
  if (points > kInProcessMaxPoints) return "";
  return "small job (" + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]) +
         " grid points, at most 64^3): computed in-process, as starting workers would cost more; --workers N to use them";
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
  } catch (const farm::JournalIoError& e) {
    throw ioError(e.what());  // a full disk under the journal is an I/O error, as for the output
  } catch (const std::bad_alloc&) {
    throw CliError(kExitInternal, "out of memory while running the job (a larger machine, or a smaller --res)");
  } catch (const std::runtime_error& e) {
    throw CliError(kExitFarmError, e.what());
  }
}

namespace {

void writeReportBytes(io::AtomicOutput& reportOut, const farm::FarmReport& report) {
  farm::FarmReport final = report;
  final.peakRssBytes = farm::peakRssBytes();  // after the output was written
  std::ofstream r(reportOut.tempPath());
  r << final.toJson() << "\n";
  r.close();  // a full disk shows at the flush
  if (!r) throw ioError("cannot write the report '" + reportOut.path() + "': " + std::strerror(errno));
}

}  // namespace

void writeReport(io::AtomicOutput& reportOut, const farm::FarmReport& report) {
  writeReportBytes(reportOut, report);
  reportOut.commit();
}

void writeReportWith(io::AtomicOutput& reportOut, const farm::FarmReport& report,
                     const std::function<std::vector<std::string>()>& commitOutputs) {
  writeReportBytes(reportOut, report);
  const std::vector<std::string> outputs = commitOutputs();
  try {
    reportOut.commit();
  } catch (...) {
    for (const std::string& p : outputs) ::unlink(p.c_str());
    throw;
  }
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

std::vector<std::string> BoxCut::names() const {
  std::vector<std::string> out;
  for (int b = 0; b < 6; ++b)
    if (faces & (1u << b)) out.push_back(std::string(1, "xyz"[b / 2]) + (b % 2 ? "-max" : "-min"));
  return out;
}

std::string BoxCut::text() const {
  std::string s;
  for (const std::string& n : names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

BoxCut findBoxCut(const LoadedModel& m, const GridSpec& grid, int threads, const std::string& what) {
  BoxCut cut;
  cut.faces = facesReached(Tape::compile(m.field, 3), grid, {}, threads);
  if (cut.faces)
    spdlog::warn("the solid is cut by the box's face{} {}: {}", std::bitset<6>(cut.faces).count() > 1 ? "s" : "",
                 cut.text(), what);
  return cut;
}

void setCutBox(farm::JobSpec& job, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  job.clear_cut_lo();
  job.clear_cut_hi();
  for (int a = 0; a < 3; ++a) {
    job.add_cut_lo(lo[a]);
    job.add_cut_hi(hi[a]);
  }
}

void requireComplete(io::AtomicOutput& reportOut, const farm::FarmReport& report, bool strict) {
  if (report.extremumUncertified > 0) {
    const std::string what = std::to_string(report.extremumUncertified) + " of " +
                             std::to_string(report.extremumSearches) +
                             " extremum searches stopped at their box limit before certifying their tolerance; "
                             "the widest gap left is " + formatNumber(report.extremumWidestGap) +
                             " (raise the search's box limit or loosen its tolerance)";
    if (strict) {
      writeReport(reportOut, report);
      throw CliError(kExitUncertified, what + "; --strict: nothing written");
    }
    spdlog::warn("{}", what);
  }
  if (!report.interrupted && report.poisoned.empty()) return;
  writeReport(reportOut, report);
  if (report.interrupted)
    throw CliError(kExitInterrupted, "stopped by a signal; " +
                                         std::to_string(report.bricksComputed + report.bricksFromJournal) + " of " +
                                         std::to_string(report.bricks) +
                                         " bricks are in the journal: run the same command with --resume");
  throw CliError(kExitPoisoned, poisonedMessage(report));
}

void requireComplete(const farm::FarmReport& report) {
  if (report.interrupted) throw CliError(kExitInterrupted, "stopped by a signal; nothing was written");
  if (report.poisoned.empty()) return;
  std::string s = std::to_string(report.poisoned.size()) + " tile(s) failed 3 times and were given up:";
  for (auto& p : report.poisoned)
    s += "\n  tile " + std::to_string(p.brick) + " pixels [" + std::to_string(p.lo[0]) + "," + std::to_string(p.hi[0]) +
         ")x[" + std::to_string(p.lo[1]) + "," + std::to_string(p.hi[1]) + "): " + p.error;
  throw CliError(kExitPoisoned, s);
}

std::string bricksSummary(const farm::FarmReport& report) {
  return "bricks " + std::to_string(report.bricks) + " (" + std::to_string(report.bricksComputed) + " computed, " +
         std::to_string(report.bricksFromJournal) + " from the journal), workers " +
         std::to_string(report.workersSeen) + (report.inProcessRule.empty() ? "" : " (in-process: small job)") +
         ", retries " + std::to_string(report.retries) + ", " +
         formatNumber(std::round(report.wallSeconds * 1000) / 1000) + " s" + verificationSummary(report);
}

std::string verificationSummary(const farm::FarmReport& report) {
  if (report.verifyFraction < 0) return "";
  if (!report.verifyUnavailable.empty() && report.verifiedBricks == 0)
    return "; not verified (" + report.verifyUnavailable + ")";
  return "; verified " + std::to_string(report.verifiedBricks) + " (mismatches " +
         std::to_string(report.verifyMismatches) + ", workers banned for them " + std::to_string(report.liarsBanned) +
         ", bricks recomputed " + std::to_string(report.bricksRedone) + ")";
}

}  // namespace frep::cli
