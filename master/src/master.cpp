// The job: its plan, the bricks' commits and revocations (master.h); the in-process run is
// in_process.cpp.

#include <spdlog/spdlog.h>
#include <algorithm>
#include <csignal>
#include <cstring>
#include <random>
#include <time.h>

#include "frep/farm/crc32.h"
#include "master.h"

namespace frep::farm::detail {

std::atomic<bool> gStop{false};

namespace {

void onStopSignal(int) { gStop = true; }

// Installs SIGTERM/SIGINT handlers for the lifetime of a job, restoring the old ones after.
struct SignalScope {
  struct sigaction oldTerm {}, oldInt {}, oldHup {};
  // SIGHUP too (a closed terminal): the job stops as for SIGTERM, local workers are stopped.
  SignalScope() {
    gStop = false;
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, &oldTerm);
    sigaction(SIGINT, &sa, &oldInt);
    sigaction(SIGHUP, &sa, &oldHup);
  }
  ~SignalScope() {
    sigaction(SIGTERM, &oldTerm, nullptr);
    sigaction(SIGINT, &oldInt, nullptr);
    sigaction(SIGHUP, &oldHup, nullptr);
  }
};

int decodeThreadsFor(int requested) { return requested > 0 ? requested : defaultDecodeThreads(); }

// The master process's CPU so far (FarmReport::masterCpuSeconds).
double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

Master::Master(const JobSpec& job, const FarmOptions& opt)
    : job_(job),
      opt_(opt),
      jobId_(jobIdOf(job)),
      grid_(gridOf(job)),
      op_(operationOf(job)),
      decoders_(decodeThreadsFor(opt.decodeThreads)),
      mergers_(decodeThreadsFor(opt.decodeThreads)),
      streaming_(op_ == Operation::Sample && opt.sampleSink.leaves) {
  if (opt.brickVoxels < 8 || opt.brickVoxels % 8 != 0)
    throw std::invalid_argument("--brick must be a positive multiple of 8 voxels");
  if (op_ == Operation::Render && opt.brickVoxels % kRenderTile != 0)  // castRegion's regions
    throw std::invalid_argument("--brick: a render's bricks are whole " + std::to_string(kRenderTile) +
                                "-pixel tiles: expected a multiple of " + std::to_string(kRenderTile));
  if (!opt.listen.empty() && opt.curveDir.empty() && !opt.insecure && !isLoopbackEndpoint(opt.listen))
    throw std::invalid_argument("--listen " + opt.listen +
                                ": without --curve anyone who can reach this address can join the farm and forge "
                                "results; add --curve DIR (see frep keygen) or, on a trusted network, --insecure");
  plan();
}

FarmOutcome Master::run() {
  SignalScope signals;
  start_ = Clock::now();
  const double cpu0 = processCpuSeconds();
  if (streaming_) merger_ = std::thread([this] { mergeSlabs(); });
  std::optional<uint64_t> journalSeed;
  if (!opt_.journalPath.empty()) {
    // Replayed without handing slabs to the merge thread: a record may be revoked further on.
    replaying_ = true;
    // The journal's id binds the brick edge too: a record is a brick's payload by its index in
    // the plan, so a journal of another edge (another --brick, or --workers, which chooses it)
    // would merge its bricks as other regions. It is refused as another job's.
    const uint64_t journalId = jobId_ ^ (0x9e3779b97f4a7c15ull * uint64_t(opt_.brickVoxels));
    journal_ = std::make_unique<Journal>(opt_.journalPath, journalId, opt_.resume, [&](uint64_t id, const std::string& payload) {
      if ((id == kJournalVerifySeed || id == kJournalRevoke) && payload.size() == 8) {
        uint64_t v = 0;
        std::memcpy(&v, payload.data(), 8);
        if (id == kJournalVerifySeed) journalSeed = v;
        else if (v < bricks_.size() && lease(v).phase == BrickPhase::Done) uncommit(v);
        return;
      }
      if (id >= bricks_.size() || lease(id).phase == BrickPhase::Done) return;
      BrickOutput out;
      KeptBrick kept;
      std::string err;
      if (!verifyPayload(payload.data(), payload.size(), bricks_[id], out, kept, &err)) return;
      if (op_ == Operation::Sample) kept.payload = arena_.add(payload.data(), payload.size());
      commit(id, std::move(out), "journal", false, std::move(kept));
      ++report_.bricksFromJournal;
    });
    replaying_ = false;
    if (report_.bricksFromJournal)
      spdlog::info("resumed {} of {} bricks from {}", report_.bricksFromJournal, bricks_.size(), opt_.journalPath);
  }
  setUpVerification(journalSeed);
  if (streaming_) queueCompleteSlabs();
  progress_ = std::make_unique<Progress>(opt_.progressBar, opt_.progressJson, bricks_.size());
  if (!leases_.over()) {
    if (opt_.workers == 0 && opt_.listen.empty()) runInProcess();
    else runFarm();
  }
  progress_->finish(leases_.done(), report_.pointEvals, int(peers().size()));
  // To the disk when a resume will read it (stopped, or bricks poisoned). A finished job's
  // journal is removed once the output is written (frep sample/mesh), usually before the
  // kernel writes it back at all: syncing it took 0.18 s of a 1.2 s job (4096 bricks,
  // 600 MB). It stays in the page cache meanwhile, so only a crash of the machine itself
  // while the output is written can lose records, which a resume recomputes.
  if (journal_ && leases_.done() < bricks_.size()) journal_->flush();
  const double cpuLoop = processCpuSeconds();
  reportWorkerTime();
  FarmOutcome outcome = finish();
  const double cpu1 = processCpuSeconds();
  outcome.report.masterCpuSeconds = cpu1 - cpu0;
  outcome.report.masterCpuAfterLastBrick = cpu1 - cpuLoop;
  return outcome;
}

// --verify (FarmOptions::verifyFraction): the sample's seed (the journal's on a resume, else the
// options', else a random one, written to the journal), whether two workers can be compared at
// all, and the bricks of the sample.
void Master::setUpVerification(std::optional<uint64_t> journalSeed) {
  report_.verifyFraction = opt_.verifyFraction;
  if (opt_.verifyFraction < 0) return;
  fraction_ = std::min(1.0, opt_.verifyFraction);
  if (journalSeed) seed_ = *journalSeed;
  else if (opt_.verifySeed) seed_ = opt_.verifySeed;
  else {
    std::random_device rd;
    seed_ = (uint64_t(rd()) << 32 ^ rd()) | 1;
  }
  if (journal_ && !journalSeed) journal_->add(kJournalVerifySeed, &seed_, 8, crc32Of(&seed_, 8));
  report_.verifySeed = seed_;
  std::string unavailable;
  if (opt_.workers == 0 && opt_.listen.empty())
    unavailable = "--workers 0 computes in-process: there are no workers to compare";
  else if (opt_.listen.empty() && localWorkerCount() == 1)
    unavailable = "one local worker: there is no second worker to compute a brick again";
  if (!unavailable.empty()) {
    report_.verifyUnavailable = unavailable;
    spdlog::warn("--verify cannot run: {}; the results are merged unchecked", unavailable);
    return;
  }
  if (!opt_.listen.empty() && opt_.expectWorkers == 1)
    spdlog::warn("--verify with --expect-workers 1: a checked brick waits for a second worker (up to {} s, then it "
                 "is merged unchecked)", opt_.noWorkerTimeoutSec);
  verifyOn_ = true;
  for (Brick& b : bricks_)
    if (lease(b.id).phase != BrickPhase::Done) b.verify = verifySelected(jobId_, seed_, b.id, fraction_);
}

uint32_t Master::workerIndex(const std::string& workerId) {
  auto [it, added] = workerIndex_.try_emplace(workerId, uint32_t(workerNames_.size()));
  if (added) workerNames_.push_back(workerId);
  return it->second;
}

void Master::plan() {
  const int b = opt_.brickVoxels;
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = (grid_.dims[a] + b - 1) / b;
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        Brick br;
        br.id = bricks_.size();
        br.lo = {i * b, j * b, k * b};
        br.hi = {std::min((i + 1) * b, grid_.dims[0]), std::min((j + 1) * b, grid_.dims[1]),
                 std::min((k + 1) * b, grid_.dims[2])};
        size_t leaves = 1;
        for (int a = 0; a < 3; ++a) leaves *= size_t((br.hi[a] - br.lo[a] + 7) / 8);
        br.maxLeaves = leaves;
        bricks_.push_back(br);
      }
  leases_ = LeaseTable(bricks_.size(), leasePolicy(),
                       {[this](uint64_t id, const std::string& why, const std::string& count) { onPoisoned(id, why, count); },
                        [this](uint64_t id, const std::string& w) { return holdsOpinion(bricks_[id], w); }});
  if (op_ == Operation::Sample) kept_.resize(bricks_.size());
  else outputs_.resize(bricks_.size());
  perSlab_ = size_t(n[1]) * size_t(n[2]);
  for (size_t first = 0; first < bricks_.size(); first += perSlab_)
    slabLeft_.push_back(std::min(perSlab_, bricks_.size() - first));
  report_.bricks = bricks_.size();
  size_t leaves = 0;
  for (auto& br : bricks_) leaves = std::max(leaves, br.maxLeaves);
  payloadLimit_ = 12 + leaves * (16 + 64 + 2048) + leaves * 8 * 20 + 4096;
  if (op_ == Operation::Mesh) {
    // At most 8 vertices per grid point (7 edges and a feature vertex; a varint key and 6
    // doubles each, and maybe a carried quadric: a varint, 11 doubles and a flag) and 12
    // triangles per cell (3 varints of at most 5 bytes each and a state byte).
    const size_t b = size_t(opt_.brickVoxels);
    payloadLimit_ = 4096 + 8 * (b + 1) * (b + 1) * (b + 1) * (10 + 48 + 5 + 88 + 1) + 12 * b * b * b * 16;
  }
  if (op_ == Operation::Render) {  // a kind byte and 7 doubles per pixel
    const size_t b = size_t(opt_.brickVoxels);
    payloadLimit_ = 4096 + b * b * (1 + 7 * 8);
  }
}

// A brick's result is final: keep it (for "sample", `kept`; out's leaves are not kept), count it.
// `verified`: two distinct workers returned its bytes. A tainted brick (uncommit) is only counted:
// its slab is the merge thread's, and its record is in the journal, which runJob merges again.
void Master::commit(uint64_t id, BrickOutput&& out, const std::string& who, bool computed, KeptBrick&& kept,
            bool verified) {
  Brick& b = bricks_[id];
  leases_.complete(id);
  b.verified = verified;
  b.mergedFrom = computed ? workerIndex(who) : kFromJournal;
  if (verified) ++report_.verifiedBricks;
  if (op_ == Operation::Sample && !std::exchange(b.tainted, false)) {
    report_.leaves += kept.origins.size();
    report_.tiles += kept.tiles.size();
    kept_[id] = std::move(kept);
    if (streaming_ && --slabLeft_[id / perSlab_] == 0 && !replaying_) queueCompleteSlabs();
  }
  if (computed) {
    ++report_.bricksComputed;
    report_.pointEvals += out.stats.pointEvals;
    report_.intervalEvals += out.stats.intervalEvals;
    report_.nanValues += out.stats.nanValues;
    report_.domainErrors.add(out.stats.domainErrors);
    report_.extremumSearches += out.extremumSearches;
    report_.extremumUncertified += out.extremumUncertified;
    report_.extremumSignDecided += out.extremumSignDecided;
    report_.extremumWidestGap = std::max(report_.extremumWidestGap, out.extremumWidestGap);
    leases_.credit(who);
    auto& share = report_.perWorker[who];
    ++share.bricks;
    share.pointEvals += out.stats.pointEvals;
  }
  if (op_ != Operation::Sample) outputs_[id] = std::move(out);
}

// Takes a merged brick back to be computed again (its worker was convicted of forging, or is
// under suspicion; or, replaying, the journal revokes it): a revocation goes to the journal, so
// a resume does not merge its record either. A "sample" brick whose slab was already handed to
// the merge thread cannot leave the stream: it is tainted (streamTainted_), computed again into
// the journal only, and runJob merges the whole job once more from the journal.
void Master::uncommit(uint64_t id) {
  Brick& b = bricks_[id];
  if (lease(id).phase != BrickPhase::Done) return;
  if (journal_ && !replaying_) {
    const uint64_t v = id;
    journal_->add(kJournalRevoke, &v, 8, crc32Of(&v, 8));
  }
  leases_.reopen(id, !replaying_);  // replaying: still queued from the plan
  if (b.mergedFrom == kFromJournal) {
    if (report_.bricksFromJournal) --report_.bricksFromJournal;
  } else {
    --report_.bricksComputed;
    auto& share = report_.perWorker[workerNames_[b.mergedFrom]];
    if (share.bricks) --share.bricks;
  }
  if (b.verified && report_.verifiedBricks) --report_.verifiedBricks;
  b.verified = false;
  b.mergedFrom = kFromJournal;
  if (op_ == Operation::Sample) {
    if (streaming_ && id / perSlab_ < slabsQueued_) {
      b.tainted = streamTainted_ = true;
    } else {
      report_.leaves -= kept_[id].origins.size();
      report_.tiles -= kept_[id].tiles.size();
      kept_[id] = KeptBrick{};
      if (streaming_) ++slabLeft_[id / perSlab_];
    }
  } else {
    outputs_[id] = BrickOutput{};
  }
}

}  // namespace frep::farm::detail
