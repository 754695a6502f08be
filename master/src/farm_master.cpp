// The master's public entry points (farm_master.h): runJob, the report's JSON, and helpers.
#include "frep/master/farm_master.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include <tbb/task_arena.h>

#include "master.h"

namespace frep::farm {

using detail::Master;

std::string FarmReport::toJson() const {
  nlohmann::json j;
  j["wall_seconds"] = wallSeconds;
  j["peak_rss_bytes"] = peakRssBytes;
  j["bricks"] = {{"total", bricks}, {"computed", bricksComputed}, {"from_journal", bricksFromJournal}};
  j["evaluations"] = {{"point", pointEvals}, {"interval", intervalEvals}, {"dense_equivalent", denseEvals},
                      {"nan_values", nanValues}};
  nlohmann::json dom = nlohmann::json::object();
  for (size_t k = 0; k < kDomainErrorKinds; ++k) dom[domainErrorName(DomainError(k))] = domainErrors.n[k];
  j["domain_errors"] = dom;
  j["extremum"] = {{"searches", extremumSearches},
                   {"sign_decided", extremumSignDecided},
                   {"uncertified", extremumUncertified},
                   {"widest_uncertified_gap", extremumUncertified ? nlohmann::json(extremumWidestGap) : nlohmann::json()},
                   {"error_bounds", errorBounds}};
  j["operation"] = operation;
  if (operation == "mesh") {
    j["output"] = {{"vertices", vertices}, {"triangles", triangles}, {"capped", capped}};
    j["surface_error_bound"] = surfaceErrorBound;
    if (simplifyTolerance > 0)
      j["output"]["simplification"] = {{"tolerance_voxels", simplifyTolerance},
                                       {"sharp_features", sharpFeatures},
                                       {"triangles_before", simplify.trianglesBefore},
                                       {"collapses", simplify.collapses},
                                       {"error_bound", simplify.errorBound},
                                       {"model_evaluations", simplify.modelEvals},
                                       {"rejected", {{"topology", simplify.rejectedTopology},
                                                     {"shape", simplify.rejectedShape},
                                                     {"error", simplify.rejectedError},
                                                     {"intersection", simplify.rejectedIntersection}}}};
  }
  else if (operation == "render") j["output"] = {{"pixels_hit", pixelsHit}};
  else j["output"] = {{"leaves", leaves}, {"tiles", tiles}};
  if (operation != "render") j["output"]["cut_faces"] = cutFaces;
  j["faults"] = {{"retries", retries},           {"duplicates", duplicates},
                 {"late_results", lateResults},  {"malformed", malformed},
                 {"oversized", oversized},       {"dead_workers", deadWorkers},
                 {"handed_back", handedBack},    {"straggler_reissues", stragglerReissues},
                 {"queued_reissues", queuedReissues}, {"lease_reissues", leaseReissues}, {"refused", refused},
                 {"curve_rejected", curveRejected}, {"foreign_results", foreignResults},
                 {"banned_peers", bannedPeers},  {"suspect_bricks", suspectBricks},
                 {"reconnects", reconnects},     {"master_stalls", masterStalls},
                 {"refuted_failures", refutedFailures}, {"failing_peers_banned", failingPeersBanned}};
  char seed[17];
  std::snprintf(seed, sizeof seed, "%016llx", static_cast<unsigned long long>(verifySeed));
  j["verification"] = {{"fraction", verifyFraction >= 0 ? nlohmann::json(verifyFraction) : nlohmann::json()},
                       {"seed", verifyFraction >= 0 ? nlohmann::json(seed) : nlohmann::json()},
                       {"verified_bricks", verifiedBricks},
                       {"verify_mismatches", verifyMismatches},
                       {"liars_banned", liarsBanned},
                       {"bricks_redone", bricksRedone},
                       {"unverified_bricks", unverifiedBricks},
                       {"unavailable", verifyUnavailable.empty() ? nlohmann::json() : nlohmann::json(verifyUnavailable)},
                       {"restreamed", restreamed}};
  j["workers_seen"] = workersSeen;
  j["in_process_rule"] = inProcessRule.empty() ? nlohmann::json() : nlohmann::json(inProcessRule);
  j["master_cpu_seconds"] = masterCpuSeconds;
  j["master_cpu_after_last_brick"] = masterCpuAfterLastBrick;
  nlohmann::json w = nlohmann::json::object();
  for (auto& [id, s] : perWorker)
    w[id] = {{"bricks", s.bricks},
             {"point_evals", s.pointEvals},
             {"compute_seconds", s.computeSeconds},
             {"results", s.results},
             {"compute_cpu_seconds", s.computeCpuSeconds},
             {"task_cpu_seconds", s.taskCpuSeconds},
             {"process_cpu_seconds", s.processCpuSeconds},
             {"idle_seconds", s.idleSeconds},
             {"first_idle_seconds", s.firstIdleSeconds},
             {"tail_idle_seconds", s.tailIdleSeconds},
             {"share", pointEvals ? double(s.pointEvals) / double(pointEvals) : 0.0}};
  j["per_worker"] = w;
  nlohmann::json p = nlohmann::json::array();
  for (auto& b : poisoned)
    p.push_back({{"brick", b.brick}, {"lo", b.lo}, {"hi", b.hi}, {"error", b.error}});
  j["poisoned"] = p;
  j["interrupted"] = interrupted;
  return j.dump(2);
}

FarmOutcome runJob(const JobSpec& job, const FarmOptions& options) {
  FarmOutcome first = Master(job, options).run();
  if (!first.report.restreamed) return first;
  // A convicted worker's bricks were in slabs the sink already had: its results must not stay in
  // the output. The journal holds the job as it must be (their records revoked, computed again):
  // the sink starts over and the job is merged once more from the journal, in-process should a
  // brick be missing there (none is).
  if (!options.sampleSink.restart || options.journalPath.empty())
    throw std::runtime_error("a worker convicted of forging results had bricks in slabs already streamed, and the stream "
                             "cannot be restarted (it needs SampleSink::restart and a journal)");
  spdlog::warn("a worker convicted of forging results had bricks in slabs already written: merging the whole job again "
               "from the journal");
  options.sampleSink.restart();
  FarmOptions again = options;
  again.resume = true;
  again.workers = 0;
  again.listen.clear();
  again.verifyFraction = -1;
  again.progressBar = again.progressJson = false;
  again.onListening = nullptr;
  FarmOutcome second = Master(job, again).run();
  if (second.report.bricksFromJournal != second.report.bricks)
    spdlog::warn("{} brick(s) were missing from the journal and computed in-process",
                 second.report.bricks - second.report.bricksFromJournal);
  FarmReport r = first.report;  // the job's counters; the output's from the second merge
  r.leaves = second.report.leaves;
  r.tiles = second.report.tiles;
  r.wallSeconds += second.report.wallSeconds;
  r.peakRssBytes = std::max(r.peakRssBytes, second.report.peakRssBytes);
  r.poisoned = second.report.poisoned;
  r.interrupted = second.report.interrupted;
  second.result.stats = first.result.stats;
  second.report = std::move(r);
  return second;
}

namespace {
uint64_t mix64(uint64_t z) {  // splitmix64's finalizer
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
}  // namespace

bool verifySelected(uint64_t jobId, uint64_t seed, uint64_t brick, double fraction) {
  if (fraction >= 1) return true;
  if (!(fraction > 0)) return false;
  const uint64_t h = mix64(mix64(jobId ^ mix64(seed)) ^ brick);
  return double(h >> 11) * 0x1.0p-53 < fraction;
}

bool isLoopbackEndpoint(const std::string& endpoint) {
  if (endpoint.rfind("tcp://", 0) != 0) return false;
  std::string host = endpoint.substr(6, endpoint.rfind(':') == std::string::npos ? std::string::npos : endpoint.rfind(':') - 6);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

uint64_t peakRssBytes() {
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
  return uint64_t(ru.ru_maxrss) * 1024;  // kilobytes on Linux
}

// More decode threads than this only add TBB workers that spin for work between batches on the
// cores the loop needs: on 2 cores, 125 against 148 us of master CPU a streamed brick
// (docs/farm.md, "Throughput").
int defaultDecodeThreads() { return std::max(1, tbb::this_task_arena::max_concurrency() - 2); }

}  // namespace frep::farm
