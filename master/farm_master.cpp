// The master's scheduling loop (see farm_master.h and docs/farm.md for the guarantees).
#include "farm_master.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstring>
#include <deque>
#include <exception>
#include <fstream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <thread>
#include <utility>
#include <zmq.hpp>

#include <string_view>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "brick.h"
#include "curve.h"
#include "frep/meshing/mesh_merge.h"
#include "allocator_tuning.h"
#include "journal.h"
#include "leaf_order.h"
#include "leaf_records.h"
#include "local_workers.h"
#include "payload_arena.h"
#include "progress.h"
#include "wire.h"

namespace frep::farm {

namespace {

using Clock = std::chrono::steady_clock;
std::atomic<bool> gStop{false};
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

constexpr size_t kMaxEnvelopeBytes = 1 << 20;  // a task or result header is a few KB at most
constexpr int kCredit = 4;                     // bricks in flight per worker (hides latency)
// Hostile peers (docs/farm.md, "Threat model"): an un-welcomed routing id may send only a
// hello, checked before parsing; garbage bans its routing id. The ban list and the welcomed
// workers are bounded so strangers cannot grow the master's state without limit.
constexpr size_t kMaxHelloBytes = 64 << 10;
constexpr size_t kMaxBanned = 1024;     // banned routing ids remembered (oldest forgotten)
constexpr size_t kMaxPeers = 4096;      // welcomed workers at once; a hello beyond is refused
constexpr size_t kMaxAliases = 4096;    // routing ids of workers that reconnected
// Failing peers (docs/farm.md, "Failing peers"): a brick is poisoned only when kIndependentFailures
// workers (distinct worker ids) failed it; a worker that failed a brick is not given it again
// while another could take it (Master::mayTake); a worker whose failures other workers refuted
// (they computed the brick it failed) reach kBanAfterRefuted and more than twice the lower median
// of the other peers' refuted failures is banned: told bye, its worker id refused from then on.
constexpr size_t kIndependentFailures = 2;
constexpr uint64_t kBanAfterRefuted = 3;
constexpr size_t kMaxSkippedForPeer = 64;  // bricks a peer failed passed over per dispatch (bounded scan)
constexpr int kRouterRcvHwm = 64;       // queued messages per connection (ZMQ_RCVHWM)
// Verification (docs/farm.md, "Verification"): a checked brick is merged once two distinct
// workers returned the same bytes; this many different results without two agreeing poison it
// (the computation is not deterministic across these workers: other builds or machines).
constexpr size_t kMaxOpinions = 4;
constexpr uint32_t kFromJournal = ~uint32_t(0);  // Brick::mergedFrom of a brick replayed from the journal
// Results received in a row are verified and decoded together on the decode threads; a batch
// ends at a message of another kind, at the end of a turn's drain, or at these bounds.
constexpr size_t kMaxArrivals = 64;
constexpr size_t kMaxArrivalBytes = 64 << 20;

// A received message kept for the merge, counted against the master's budget while it lives.
class HeldPayload {
 public:
  HeldPayload() = default;
  // Takes `message` if the held bytes stay within `budget`; else leaves it.
  static HeldPayload take(zmq::message_t& message, std::atomic<size_t>& held, size_t budget) {
    HeldPayload h;
    const size_t size = message.size();
    if (held.fetch_add(size, std::memory_order_relaxed) + size > budget) {
      held.fetch_sub(size, std::memory_order_relaxed);
      return h;
    }
    h.message_ = std::move(message);
    h.held_ = &held;
    return h;
  }
  HeldPayload(HeldPayload&& o) noexcept { *this = std::move(o); }
  HeldPayload& operator=(HeldPayload&& o) noexcept {
    if (this != &o) {
      release();
      message_ = std::move(o.message_);
      held_ = std::exchange(o.held_, nullptr);
    }
    return *this;
  }
  ~HeldPayload() { release(); }
  bool held() const { return held_ != nullptr; }
  std::string_view bytes() const { return {static_cast<const char*>(message_.data()), message_.size()}; }

 private:
  void release() {
    if (held_) held_->fetch_sub(message_.size(), std::memory_order_relaxed);
    held_ = nullptr;
    message_ = zmq::message_t();
  }
  zmq::message_t message_;
  std::atomic<size_t>* held_ = nullptr;
};

enum class Departure { Left, Dead, Dropped };

enum class BrickPhase { Pending, Leased, Done, Poisoned };

struct Brick {
  uint64_t id = 0;
  std::array<int32_t, 3> lo{}, hi{};
  BrickPhase phase = BrickPhase::Pending;
  int failures = 0;  // failed attempts reported by its holder (and corrupt results from it)
  std::set<std::string> failedBy;  // worker ids of those holders (not banned ones: unban on ban)
  Clock::time_point lastFailure{};
  // Worker deaths (docs/farm.md, "Faults"): the first death of a worker computing it makes it
  // suspect; a suspect is leased only alone to a worker that has shown it is alive, and each
  // such worker that dies with it counts; killers.size() >= maxAttempts poisons it.
  bool suspect = false;
  Clock::time_point suspectSince{};
  std::set<std::string> killers;      // fresh workers (nothing finished) that died with it alone
  std::set<std::string> weakKillers;  // workers that had finished other bricks
  uint32_t attempts = 0;
  std::map<std::string, Clock::time_point> holders;  // routing id -> lease start
  Clock::time_point firstLease{};
  bool backupIssued = false, leaseReissued = false;
  std::string lastError;
  size_t maxLeaves = 0;  // upper bound on leaves in the region (payload sanity check)
  // Verification: `verify`, merged only once two distinct workers returned the same bytes (in
  // the sample, a suspect's, or recomputed for a convicted worker); `held`, results of it wait
  // in Master::verifying_; `verified`, merged so; `tainted`, taken back after its slab went to
  // the merge thread (its new result goes to the journal only: runJob merges again from there);
  // mergedFrom, the worker whose result was merged (Master::workerNames_), or kFromJournal.
  bool verify = false, held = false, verified = false, tainted = false;
  uint32_t mergedFrom = kFromJournal;
};

// A result of a brick under verification, held until another worker returns the same bytes.
struct Opinion {
  std::string workerId;
  Result result;          // its counters, merged with it
  zmq::message_t bytes;   // its payload, as received (CRC and codec checked)
};
struct Verification {
  std::vector<Opinion> opinions;  // of distinct workers, all different bytes
  Clock::time_point starvedSince{};  // since when no connected worker could give the next one
  bool starved = false;
};

// "sample": what the master keeps of a merged brick until its slab is merged: where its verified
// FRB2 payload is (compact leaves take about half the bytes of decoded ones): with a journal, the
// message as received while the held bytes stay within FarmOptions::heldPayloadBytes (reading the
// journal's copy back and checking its CRC again took ~12% of the streamed master's CPU), else
// the journal's copy (page cache, not the master's memory); without a journal, a copy in the
// payload arena; and its leaves' origins (where they go in the sorted output) and records (where
// each starts in the payload), and its tiles. Verifying a payload only scans it (scanBrick); its
// slab's merge decodes each leaf once, in sorted order (Master::slabRecords: streaming, once the
// slab's bricks are all in; else in finish()).
struct KeptBrick {
  PayloadArena::Piece payload;  // without a journal
  HeldPayload received;         // with one, within the budget
  bool inJournal = false;       // with one: the payload's offset, size and CRC-32 there
  uint64_t journalAt = 0, size = 0;
  uint32_t crc = 0;
  std::vector<std::array<int32_t, 3>> origins;  // of its leaves, in payload order
  std::vector<uint32_t> leafAt;                 // where each leaf's record starts in the payload
  std::vector<Tile> tiles;
};

// A result from its brick's holder, waiting to be verified (CRC, codec, inside the brick) and
// decoded off the scheduling loop (Master::verifyArrivals).
struct Arrival {
  uint64_t brick = 0;
  std::string routingId, workerId;
  Result result;
  zmq::message_t payload;
  BrickOutput out;  // "mesh", "render": the decoded result
  KeptBrick kept;   // "sample": where the payload is kept (journal or arena), origins and tiles
  std::string error;
  bool ok = false;
  bool check = false;      // under verification: payload kept for the judge, not journaled yet
  bool journaled = false;  // appended to the journal (a copy not merged is then revoked there)
};

struct Peer {
  std::string workerId;
  uint32_t threads = 1;
  Clock::time_point expiry;
  std::set<uint64_t> inflight;
  std::set<uint64_t> everHeld;  // a later copy from a former holder is a duplicate, not foreign
  bool proven = false;          // sent something after its hello (it lives past a task)
  bool unreachable = false;     // no route to it: no more tasks (sendTask)
  uint64_t finished = 0;        // bricks it computed that were merged
  uint64_t failures = 0;        // bricks it reported failed (not handed back)
  uint64_t refuted = 0;         // ... of which another worker then computed
  std::vector<uint64_t> failedBricks;  // the bricks it failed, to clear them if it is banned
};

int decodeThreadsFor(int requested) { return requested > 0 ? requested : defaultDecodeThreads(); }

// The master socket's kernel receive buffer (ZMQ_RCVBUF; 0: the kernel's own). Results are large
// (a sample brick ~150 kB), and on a short round trip (local workers, a LAN) receive autotuning
// sizes each connection's window to the tiny bandwidth-delay product, below one result, so a
// result crossed in several window updates: a fixed 4 MiB took the senders 61 -> 52 us of CPU a
// brick and the master 1.06x the bricks a second (bench_farm, 30 runs each, alternated). A fixed
// buffer turns autotuning off and the kernel caps it at net.core.rmem_max: it is set only where
// that allows 1 MiB or more (a fixed 208 KiB, Debian's default cap, was 0.78x the rate).
int receiveBufferBytes() {
  std::ifstream f("/proc/sys/net/core/rmem_max");
  long long allowed = 0;
  if (!(f >> allowed) || allowed < (1 << 20)) return 0;
  return int(std::min<long long>(allowed, 4 << 20));
}

class Master {
 public:
  Master(const JobSpec& job, const FarmOptions& opt)
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

  ~Master() { stopMerger(); }

  FarmOutcome run() {
    SignalScope signals;
    start_ = Clock::now();
    if (streaming_) merger_ = std::thread([this] { mergeSlabs(); });
    std::optional<uint64_t> journalSeed;
    if (!opt_.journalPath.empty()) {
      // Replayed without handing slabs to the merge thread: a record may be revoked further on.
      replaying_ = true;
      journal_ = std::make_unique<Journal>(opt_.journalPath, jobId_, opt_.resume, [&](uint64_t id, const std::string& payload) {
        if ((id == kJournalVerifySeed || id == kJournalRevoke) && payload.size() == 8) {
          uint64_t v = 0;
          std::memcpy(&v, payload.data(), 8);
          if (id == kJournalVerifySeed) journalSeed = v;
          else if (v < bricks_.size() && bricks_[v].phase == BrickPhase::Done) uncommit(v);
          return;
        }
        if (id >= bricks_.size() || bricks_[id].phase == BrickPhase::Done) return;
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
    if (done_ + poisoned_ < bricks_.size()) {
      if (opt_.workers == 0 && opt_.listen.empty()) runInProcess();
      else runFarm();
    }
    progress_->finish(done_, report_.pointEvals, int(peers_.size()));
    // To the disk when a resume will read it (stopped, or bricks poisoned). A finished job's
    // journal is removed once the output is written (frep sample/mesh), usually before the
    // kernel writes it back at all: syncing it took 0.18 s of a 1.2 s job (4096 bricks,
    // 600 MB). It stays in the page cache meanwhile, so only a crash of the machine itself
    // while the output is written can lose records, which a resume recomputes.
    if (journal_ && done_ < bricks_.size()) journal_->flush();
    return finish();
  }

 private:
  // --verify (FarmOptions::verifyFraction): the sample's seed (the journal's on a resume, else the
  // options', else a random one, written to the journal), whether two workers can be compared at
  // all, and the bricks of the sample.
  void setUpVerification(std::optional<uint64_t> journalSeed) {
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
      if (b.phase != BrickPhase::Done) b.verify = verifySelected(jobId_, seed_, b.id, fraction_);
  }

  int localWorkerCount() const {
    return opt_.workers > 0 ? opt_.workers : int(std::max(1u, std::thread::hardware_concurrency()));
  }

  uint32_t workerIndex(const std::string& workerId) {
    auto [it, added] = workerIndex_.try_emplace(workerId, uint32_t(workerNames_.size()));
    if (added) workerNames_.push_back(workerId);
    return it->second;
  }

  void plan() {
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
          pending_.push_back(br.id);
        }
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
  void commit(uint64_t id, BrickOutput&& out, const std::string& who, bool computed, KeptBrick&& kept = {},
              bool verified = false) {
    Brick& b = bricks_[id];
    b.phase = BrickPhase::Done;
    for (auto& [rid, t] : b.holders)  // cancelled copies no longer take a worker's credit
      if (auto p = peers_.find(rid); p != peers_.end()) p->second.inflight.erase(id);
    b.holders.clear();
    leased_.erase(id);
    ++done_;
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
      for (auto& [rid, p] : peers_)
        if (p.workerId == who) ++p.finished;
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
  void uncommit(uint64_t id) {
    Brick& b = bricks_[id];
    if (b.phase != BrickPhase::Done) return;
    if (journal_ && !replaying_) {
      const uint64_t v = id;
      journal_->add(kJournalRevoke, &v, 8, crc32Of(&v, 8));
    }
    b.phase = BrickPhase::Pending;
    --done_;
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
    if (replaying_) return;  // still in pending_ from plan()
    b.backupIssued = b.leaseReissued = false;
    pending_.push_front(id);
  }

  void runInProcess() {
    TapePtr tape = compileJobModel(job_);
    describeErrorBounds(*tape, &report_.errorBounds);
    for (const std::string& line : describeExactTerms(job_)) report_.errorBounds.push_back(line);
    for (Brick& b : bricks_) {
      if (b.phase == BrickPhase::Done) continue;
      if (gStop) {
        report_.interrupted = true;
        return;
      }
      rethrowMergeError();
      auto t0 = Clock::now();
      BrickOutput out = computeBrick(tape, job_, b.lo, b.hi, opt_.threads);
      report_.perWorker["in-process"].computeSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
      KeptBrick kept;
      if (journal_ || op_ == Operation::Sample) {
        const std::string payload = encodePayload(op_, out);
        std::string err;
        if (op_ == Operation::Sample && !scanBrick(payload.data(), payload.size(), kept.origins, kept.tiles, kept.leafAt, &err))
          throw std::logic_error("brick " + std::to_string(b.id) + ": its own payload does not scan: " + err);
        journalAndKeep(b.id, payload.data(), payload.size(), crc32Of(payload.data(), payload.size()), kept);
      }
      commit(b.id, std::move(out), "in-process", true, std::move(kept));
      progress_->update(done_, report_.pointEvals, 1);
    }
  }

  // ---- the farm -------------------------------------------------------------------------

  void runFarm() {
    // Compile once here too: a model that does not compile fails before any worker starts.
    describeErrorBounds(*compileJobModel(job_), &report_.errorBounds);
    for (const std::string& line : describeExactTerms(job_)) report_.errorBounds.push_back(line);
    zmq::context_t ctx(1);
    std::unique_ptr<ZapAuthenticator> zap;
    CurveKeys keys;
    if (!opt_.curveDir.empty()) {
      keys = loadCurveKeys(opt_.curveDir, true);
      zap = std::make_unique<ZapAuthenticator>(ctx, keys.authorized);
    }
    zmq::socket_t router(ctx, zmq::socket_type::router);
    router.set(zmq::sockopt::linger, 0);
    router.set(zmq::sockopt::router_mandatory, 1);
    // ZMQ_MAXMSGSIZE is socket-wide (every peer, welcomed or not) and per frame: the largest
    // frame this job can need. A bigger frame makes ZeroMQ close that connection before it
    // allocates the frame. ZMQ_RCVHWM bounds the frames queued per connection; the per-peer
    // hello limit is ours (frameLimit), checked before parsing.
    router.set(zmq::sockopt::maxmsgsize, int64_t(std::min<size_t>(std::max(kMaxEnvelopeBytes, payloadLimit_), 256u << 20)));
    router.set(zmq::sockopt::rcvhwm, kRouterRcvHwm);
    if (const int bytes = receiveBufferBytes()) router.set(zmq::sockopt::rcvbuf, bytes);  // before bind: accepted connections inherit it
    if (zap) applyCurveServer(router, keys);
    std::string endpoint = opt_.listen.empty() ? "tcp://127.0.0.1:*" : opt_.listen;
    router.bind(endpoint);
    endpoint = router.get(zmq::sockopt::last_endpoint);
    spdlog::info("master listening on {}", endpoint);
    if (opt_.onListening) opt_.onListening(endpoint);
    if (opt_.progressJson)
      std::printf("{\"event\":\"listening\",\"endpoint\":\"%s\",\"bricks\":%zu}\n", endpoint.c_str(), bricks_.size()),
          std::fflush(stdout);

    std::unique_ptr<LocalWorkers> local;
    int wanted = 0;
    if (opt_.listen.empty()) {
      wanted = localWorkerCount();
      std::vector<std::string> args{"--connect", endpoint, "--threads", std::to_string(opt_.workerThreads),
                                    "--log-level", opt_.logLevel, "--master-timeout", "10"};
      if (!opt_.curveDir.empty()) args.insert(args.end(), {"--curve", opt_.curveDir});
      local = std::make_unique<LocalWorkers>(opt_.workerExecutable, args);
      local->spawn(wanted);
    }
    // Local workers that die are replaced with back-off: the delay doubles (100 ms .. 2 s)
    // while no brick finishes and resets when one does; once more workers than
    // futileLimit have been started since the last brick finished, none can: fail fast.
    const int futileLimit = wanted + 2 * (opt_.maxAttempts + 1);
    int futileSpawns = wanted, respawnDelayMs = 0;
    size_t progressAtSpawn = done_ + poisoned_;
    auto nextSpawn = Clock::now();

    auto lastBeat = Clock::now();
    auto lastAlive = Clock::now();
    auto lastTurn = Clock::now();
    const auto hb = std::chrono::milliseconds(opt_.heartbeatMs);
    const auto window = std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
    const FrameLimit frameLimit = [this](const std::string& rid) {
      return peers_.count(rid) || aliases_.count(rid) ? kMaxEnvelopeBytes + payloadLimit_ : kMaxHelloBytes;
    };
    while (done_ + poisoned_ < bricks_.size()) {
      zmq::pollitem_t item{static_cast<void*>(router), 0, ZMQ_POLLIN, 0};
      try {
        zmq::poll(&item, 1, std::chrono::milliseconds(std::max(5, opt_.heartbeatMs / 4)));
      } catch (const zmq::error_t& e) {
        if (e.num() != EINTR) throw;
      }
      if (gStop) {
        report_.interrupted = true;
        spdlog::warn("stop requested: no more dispatching, journal flushed; continue with --resume");
        break;
      }
      // Drain at most a bounded batch per turn so timers still run under a flood.
      for (int n = 0; n < 256; ++n) {
        Incoming in;
        std::string err;
        if (!receive(router, true, in, &err, frameLimit)) break;
        // Only results in a row share a batch: anything else sees the state they leave.
        if (!err.empty() || in.envelope.body_case() != Envelope::kResult) verifyArrivals(router);
        handle(router, in, err);
      }
      verifyArrivals(router);
      rethrowMergeError();
      auto now = Clock::now();
      // The master's own stall (SIGSTOP, swapping, a slow disk): a turn is at most a poll
      // (a quarter beat) and a bounded drain, so a gap longer than the liveness window means
      // the master was deaf, not its peers silent. Refresh every peer instead of counting them
      // dead, and move the lease timers on (steady clock: wall-clock jumps do not count).
      if (now - lastTurn > window) {
        ++report_.masterStalls;
        auto gap = now - lastTurn;
        spdlog::warn("the master stalled for {:.1f} s (longer than the liveness window): its workers are not counted dead",
                     std::chrono::duration<double>(gap).count());
        for (auto& [rid, p] : peers_) p.expiry = std::max(p.expiry, now + window);
        for (uint64_t id : leased_) bricks_[id].firstLease += gap;
        lastAlive = now;
      }
      lastTurn = now;
      expireDeadPeers(now);
      if (local) {
        local->reap();
        if (done_ + poisoned_ > progressAtSpawn) {
          progressAtSpawn = done_ + poisoned_;
          futileSpawns = 0;
          respawnDelayMs = 0;
        }
        int missing = wanted - local->running();
        if (missing > 0 && now >= nextSpawn && done_ + poisoned_ < bricks_.size()) {
          if (futileSpawns + missing > futileLimit)
            throw std::runtime_error("local workers keep dying: " + std::to_string(futileSpawns) +
                                     " started since the last brick finished (last one " + local->lastExit() +
                                     "); run with --log-level info, or --workers 0 to compute in-process");
          futileSpawns += missing;
          local->spawn(missing);
          respawnDelayMs = std::min(2000, respawnDelayMs ? 2 * respawnDelayMs : 100);
          nextSpawn = now + std::chrono::milliseconds(respawnDelayMs);
        }
      }
      reissueOverdue(now);
      dispatch(router, now);
      if (now - lastBeat >= hb) {
        giveUpStarvedChecks(now);
        for (auto& [rid, p] : peers_) {
          Envelope e;
          e.set_job_id(jobId_);
          e.mutable_heartbeat();
          send(router, rid, e);
        }
        lastBeat = now;
      }
      if (!peers_.empty()) lastAlive = now;
      else if (std::chrono::duration<double>(now - lastAlive).count() > opt_.noWorkerTimeoutSec) {
        throw std::runtime_error("no worker has been alive for " + std::to_string(opt_.noWorkerTimeoutSec) +
                                 " s (" + std::to_string(bricks_.size() - done_ - poisoned_) + " bricks left)");
      }
      progress_->update(done_, report_.pointEvals, int(peers_.size()));
    }
    // Tell every worker the job is over; local ones exit, cluster ones too.
    for (auto& [rid, p] : peers_) {
      Envelope e;
      e.set_job_id(jobId_);
      e.mutable_bye()->set_reason(report_.interrupted ? "master stopping" : "job done");
      send(router, rid, e);
    }
    if (zap) report_.curveRejected = zap->rejected();
    // The byes leave while the context closes (it waits for them up to the linger) instead of
    // after a fixed sleep; local workers exit on theirs while the master merges, and are reaped
    // (and signalled, should one still run) when the master is done (retired_).
    router.set(zmq::sockopt::linger, 100);
    retired_ = std::move(local);
  }

  void handle(zmq::socket_t& router, Incoming& in, const std::string& err) {
    if (banned_.count(in.routingId)) return;  // dropped for garbage before: ignored
    // A worker that reconnected speaks under its new routing id; late frames on the old one
    // are its frames too.
    if (!peers_.count(in.routingId))
      if (auto a = aliases_.find(in.routingId); a != aliases_.end() && peers_.count(a->second))
        in.routingId = a->second;
    if (!err.empty()) {
      ++(in.oversized ? report_.oversized : report_.malformed);
      spdlog::warn("dropped a malformed message from {}: {}", printable(in.routingId), err);
      ban(router, in.routingId, err);
      return;
    }
    const Envelope& e = in.envelope;
    if (e.ByteSizeLong() > kMaxEnvelopeBytes || (in.payload && in.payload->size() > payloadLimit())) {
      ++report_.oversized;
      spdlog::warn("dropped an oversized message from {}", printable(in.routingId));
      ban(router, in.routingId, "oversized message");
      return;
    }
    if (e.proto_major() != kProtoMajor) {
      ++report_.refused;
      Envelope r;
      r.mutable_reject()->set_reason("protocol major " + std::to_string(e.proto_major()) +
                                     " is not supported: this master speaks " + std::to_string(kProtoMajor) + "." +
                                     std::to_string(kProtoMinor) + " (use a frep-worker from the same release)");
      send(router, in.routingId, r);
      spdlog::warn("refused {}: protocol major {}", printable(in.routingId), e.proto_major());
      return;
    }
    auto now = Clock::now();
    auto it = peers_.find(in.routingId);
    if (e.body_case() == Envelope::kHello) {
      const std::string wid = e.hello().worker_id().empty() ? printable(in.routingId) : e.hello().worker_id();
      if (bannedWorkers_.count(wid)) {
        ++report_.refused;
        Envelope r;
        r.mutable_reject()->set_reason("worker " + wid + " was banned from this job: it failed bricks that other workers computed, or returned results other workers outvoted");
        send(router, in.routingId, r);
        return;
      }
      if (it == peers_.end() && !adoptReconnected(wid, in.routingId, e.hello()) && peers_.size() >= kMaxPeers) {
        ++report_.refused;
        Envelope r;
        r.mutable_reject()->set_reason("the farm is full (" + std::to_string(kMaxPeers) + " workers)");
        send(router, in.routingId, r);
        return;
      }
      Peer& p = peers_[in.routingId];
      p.workerId = wid;
      p.unreachable = false;  // a new connection
      p.threads = std::max(1u, e.hello().threads());
      p.expiry = now + std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
      ++report_.workersSeen;
      Envelope w;
      w.set_job_id(jobId_);
      w.mutable_welcome()->set_heartbeat_ms(uint32_t(opt_.heartbeatMs));
      w.mutable_welcome()->set_liveness(uint32_t(opt_.liveness));
      *w.mutable_welcome()->mutable_job() = job_;  // once per connection; tasks name it by jobId_
      send(router, in.routingId, w);
      spdlog::info("worker {} joined ({} threads, {})", p.workerId, p.threads, e.hello().build());
      return;
    }
    if (it == peers_.end()) {
      // A worker from before a master restart, or a stranger: ask for a hello first.
      if (e.body_case() == Envelope::kResult) ++report_.lateResults;
      Envelope r;
      r.mutable_reset();
      send(router, in.routingId, r);
      return;
    }
    Peer& p = it->second;
    p.expiry = now + std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
    p.proven = true;
    switch (e.body_case()) {
      case Envelope::kHeartbeat:
        break;
      case Envelope::kResult:
        onResult(router, in, p);
        break;
      case Envelope::kFailed:
        onFailed(e, in.routingId, p);
        break;
      case Envelope::kBye:
        spdlog::info("worker {} left: {}", p.workerId, e.bye().reason());
        dropPeer(in.routingId, Departure::Left);
        break;
      default:
        ++report_.malformed;
        break;
    }
  }

  // A hello with the worker id of a peer under another routing id: the worker reconnected
  // (its master went silent, e.g. stopped). It keeps the leases of the bricks it says it still
  // has (hello.holding); the others' results went out on the connection it closed and may be
  // lost, so those bricks go back to the queue (a late copy is a former holder's duplicate).
  // Keeping them leased would hold the worker's credit for results that never come: with every
  // worker reconnected, the job would wait for ever.
  bool adoptReconnected(const std::string& workerId, const std::string& rid, const Hello& hello) {
    auto old = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
    if (old == peers_.end()) return false;
    std::string oldRid = old->first;
    Peer moved = std::move(old->second);
    peers_.erase(old);
    const std::set<uint64_t> still(hello.holding().begin(), hello.holding().end());
    std::vector<uint64_t> lost;
    for (uint64_t id : moved.inflight) {
      auto& h = bricks_[id].holders;
      auto node = h.extract(oldRid);
      if (node && still.count(id)) {
        node.key() = rid;
        h.insert(std::move(node));
      } else {
        lost.push_back(id);
      }
    }
    for (uint64_t id : lost) {
      moved.inflight.erase(id);
      Brick& b = bricks_[id];
      if (b.phase == BrickPhase::Leased && b.holders.empty())
        requeue(b, "its result was lost when worker " + workerId + " reconnected", false);
    }
    peers_[rid] = std::move(moved);
    if (aliases_.size() >= kMaxAliases) aliases_.clear();
    aliases_[oldRid] = rid;
    ++report_.reconnects;
    spdlog::info("worker {} reconnected: it keeps {} lease(s), {} brick(s) go back to the queue", workerId,
                 peers_[rid].inflight.size(), lost.size());
    return true;
  }

  // A peer that sent garbage: a welcomed one is told bye and its bricks go back to the queue,
  // not charged; its routing id is ignored from now on (bounded list, oldest forgotten).
  void ban(zmq::socket_t& router, const std::string& rid, const std::string& why) {
    if (peers_.count(rid)) {
      Envelope bye;
      bye.set_job_id(jobId_);
      bye.mutable_bye()->set_reason("dropped by the master: " + why);
      send(router, rid, bye);
      spdlog::warn("worker {} dropped: {}", peers_[rid].workerId, why);
      dropPeer(rid, Departure::Dropped);
    }
    if (!banned_.insert(rid).second) return;
    ++report_.bannedPeers;
    bannedOrder_.push_back(rid);
    if (bannedOrder_.size() > kMaxBanned) {
      banned_.erase(bannedOrder_.front());
      bannedOrder_.pop_front();
    }
  }

  size_t payloadLimit() const { return payloadLimit_; }
  Clock::duration liveWindow() const { return std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness); }

  static std::string printable(const std::string& rid) {
    std::string s;
    for (unsigned char c : rid) s += (c >= 32 && c < 127) ? char(c) : '?';
    return s.empty() ? "?" : s;
  }

  // Only the brick's leaseholder may answer for it: anything else is foreign and dropped.
  // Returns whether `rid` holds the brick; counts a foreign message otherwise.
  bool holds(const Brick& b, const std::string& rid, const Peer& p, const char* what) {
    if (b.holders.count(rid)) return true;
    if (p.everHeld.count(b.id)) {
      ++report_.duplicates;  // a former holder's late copy (cancelled, re-leased or done)
      return false;
    }
    ++report_.foreignResults;
    spdlog::warn("dropped a {} for brick {} from {}, which does not hold it", what, b.id, p.workerId);
    return false;
  }

  void onResult(zmq::socket_t& router, Incoming& in, Peer& p) {
    const Envelope& e = in.envelope;
    const Result& r = e.result();
    uint64_t id = r.brick_id();
    if (e.job_id() != jobId_ || id >= bricks_.size() || !in.payload) {
      ++report_.malformed;
      spdlog::warn("dropped a result for an unknown job or brick from {}", p.workerId);
      return;
    }
    Brick& b = bricks_[id];
    if (!holds(b, in.routingId, p, "result")) return;
    p.inflight.erase(id);
    b.holders.erase(in.routingId);
    if (b.phase == BrickPhase::Done || b.phase == BrickPhase::Poisoned) {
      ++report_.duplicates;
      return;
    }
    // Verified and decoded with the results that arrived with it (verifyArrivals).
    Arrival a;
    a.brick = id;
    a.routingId = in.routingId;
    a.workerId = p.workerId;
    a.result = std::move(*in.envelope.mutable_result());
    a.payload = std::move(*in.payload);
    a.check = needsCheck(b, p);
    arrivalBytes_ += a.payload.size();
    arrivals_.push_back(std::move(a));
    if (arrivals_.size() >= kMaxArrivals || arrivalBytes_ >= kMaxArrivalBytes) verifyArrivals(router);
  }

  // The results received in a row: CRC, codec and bounds checked, decoded and journaled in
  // parallel on the decode threads (pure functions of each payload and its brick), then judged
  // one by one in the order they arrived, as if each had been decoded on arrival; the merged
  // output does not depend on that order anyway (outputs_ by brick, sorted in finish).
  void verifyArrivals(zmq::socket_t& router) {
    if (arrivals_.empty()) return;
    // The first unchecked copy of a brick in the batch is journaled here, before the judge merges
    // it (a copy not merged after all is revoked there); later copies and checked results (merged
    // only once another worker agrees) are journaled by the judge if it merges them.
    std::set<uint64_t> first;
    for (Arrival& a : arrivals_) a.journaled = !a.check && first.insert(a.brick).second;
    decoders_.execute([&] {
      tbb::parallel_for(size_t(0), arrivals_.size(), [&](size_t i) {
        Arrival& a = arrivals_[i];
        const void* data = a.payload.data();
        const size_t size = a.payload.size();
        const uint32_t crc = a.result.payload_crc32();
        a.ok = crc32Of(data, size) == crc && verifyPayload(data, size, bricks_[a.brick], a.out, a.kept, &a.error);
        a.journaled = a.journaled && a.ok;
        if (a.journaled) keep(a);
        // Not held: freed now, the next message's buffer reuses its memory.
        if (!a.ok || a.journaled) a.payload = zmq::message_t();
      });
    });
    for (Arrival& a : arrivals_) judge(router, a);
    arrivals_.clear();
    arrivalBytes_ = 0;
  }

  // Journals a verified payload and keeps it for the merge ("sample": the message itself while
  // the held bytes allow, with a journal; a copy in the arena without one).
  void keep(Arrival& a) {
    journalAndKeep(a.brick, a.payload.data(), a.payload.size(), a.result.payload_crc32(), a.kept);
    if (a.kept.inJournal) a.kept.received = HeldPayload::take(a.payload, heldBytes_, opt_.heldPayloadBytes);
  }

  // A copy journaled (verifyArrivals) that is not merged: void in the journal, so that a resume
  // does not merge it either. Only the batch's first copy of a brick is journaled there, so the
  // brick is not merged from another record now.
  void revokeUnmerged(const Arrival& a) {
    if (!a.journaled || !journal_) return;
    const uint64_t v = a.brick;
    journal_->add(kJournalRevoke, &v, 8, crc32Of(&v, 8));
  }

  // Whether a result of `b` from `p` is merged only once another worker returns the same bytes:
  // with --verify, a brick of the sample, one already held, or any brick of a peer under
  // suspicion (failures of it that other workers refuted).
  bool needsCheck(const Brick& b, const Peer& p) const { return verifyOn_ && (b.verify || b.held || p.refuted > 0); }

  // A result's counters (the worker's word: only the payload is checked) into its output.
  static void countersOf(const Result& r, BrickOutput& out) {
    out.stats.pointEvals = r.point_evals();
    out.stats.intervalEvals = r.interval_evals();
    out.stats.nanValues = r.nan_values();
    out.extremumSearches = r.extremum_searches();
    out.extremumUncertified = r.extremum_uncertified();
    out.extremumSignDecided = r.extremum_sign_decided();
    // A peer's gap only widens what the report admits (never a NaN, never below 0).
    out.extremumWidestGap = r.extremum_widest_gap() >= 0 ? r.extremum_widest_gap() : INFINITY;
    for (int k = 0; k < r.domain_errors_size() && k < int(kDomainErrorKinds); ++k)
      out.stats.domainErrors.n[k] = r.domain_errors(k);
  }

  void judge(zmq::socket_t& router, Arrival& a) {
    Brick& b = bricks_[a.brick];
    const uint64_t id = a.brick;
    if (banned_.count(a.routingId) || bannedWorkers_.count(a.workerId)) {
      // Its sender was dropped (garbage, or convicted) after sending it (an earlier result of
      // this batch): ignored, as a message received after the ban would have been; the brick
      // goes back.
      revokeUnmerged(a);
      if (b.phase == BrickPhase::Leased && b.holders.empty()) requeue(b, "worker " + a.workerId + " dropped", false);
      return;
    }
    if (b.phase == BrickPhase::Done || b.phase == BrickPhase::Poisoned) {
      ++report_.duplicates;  // another copy of this batch was merged first
      if (b.phase == BrickPhase::Poisoned) revokeUnmerged(a);
      return;
    }
    if (!a.ok) {
      // The holder's own brick came back corrupt: it counts as a failure of the brick (a brick
      // that breaks every worker's encoder is poisoned like one that fails), and the peer,
      // which sent garbage, is dropped.
      ++report_.malformed;
      std::string why = "corrupt result from " + a.workerId + ": " + (a.error.empty() ? "crc or bounds" : a.error);
      spdlog::warn("dropped a {}", why);
      if (b.holders.empty()) requeue(b, why, true, a.workerId);
      ban(router, a.routingId, "corrupt result for brick " + std::to_string(id));
      return;
    }
    const Result& r = a.result;
    BrickOutput& out = a.out;
    countersOf(r, out);
    report_.perWorker[a.workerId].computeSeconds += r.compute_seconds();
    brickSeconds_.push_back(r.compute_seconds());
    auto sender = peers_.find(a.routingId);
    if (!a.check && sender != peers_.end() && needsCheck(b, sender->second)) {
      // The brick must be checked since this copy arrived (its sender came under suspicion, or
      // another copy of the batch was held), and this copy was journaled unchecked and its bytes
      // let go: taken back (uncharged); the brick is computed again and checked.
      revokeUnmerged(a);
      b.verify = true;
      if (b.held) awaitAnotherWorker(b);
      else if (b.holders.empty()) requeue(b, "it is to be checked: computed again", false);
      return;
    }
    if (a.check && !decide(router, a)) return;  // held until another worker agrees (or poisoned)
    if (!a.journaled && (journal_ || op_ == Operation::Sample)) keep(a);  // checked, or a later copy of the batch
    // Other holders (straggler backups) may drop the brick.
    for (auto& [rid, t] : b.holders) {
      Envelope c;
      c.mutable_cancel()->set_brick_id(id);
      send(router, rid, c);
    }
    commit(id, std::move(out), a.workerId, true, std::move(a.kept), a.check);
    // Every other worker that failed this brick was refuted: the computation is deterministic.
    for (const std::string& w : std::vector<std::string>(b.failedBy.begin(), b.failedBy.end()))
      if (w != a.workerId) refute(router, w, id);
  }

  // Worker `workerId` failed brick `id`, which another worker then computed. A worker refuted
  // kBanAfterRefuted times and more than twice the lower median of the other peers' refuted
  // failures fails what others compute: it is banned (told bye, its worker id refused, its
  // failures no longer count against any brick). Honest workers are almost never refuted, and a
  // model that fails everywhere refutes no one (no one computes its bricks). With --verify, a
  // refuted worker is under suspicion: every result of it is checked from now on, and the
  // bricks of it merged unchecked are computed again (recheckSuspect).
  void refute(zmq::socket_t& router, const std::string& workerId, uint64_t id) {
    ++report_.refutedFailures;
    auto it = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
    if (it == peers_.end()) return;  // gone already
    Peer& p = it->second;
    if (++p.refuted == 1 && verifyOn_) recheckSuspect(workerId);
    std::vector<uint64_t> others;
    for (auto& [rid, q] : peers_)
      if (&q != &p) others.push_back(q.refuted);
    std::sort(others.begin(), others.end());
    const uint64_t median = others.empty() ? 0 : others[(others.size() - 1) / 2];
    if (p.refuted < kBanAfterRefuted || p.refuted <= 2 * median) return;
    spdlog::warn("worker {} banned: {} of its {} failures were computed by other workers (brick {} last)", workerId,
                 p.refuted, p.failures, id);
    ++report_.failingPeersBanned;
    banWorker(router, workerId, "it failed " + std::to_string(p.refuted) + " bricks that other workers computed");
  }

  // Bans a worker id for the rest of the job: its failures and its held results no longer count
  // against or for any brick, its worker id is refused when it says hello again (bounded list),
  // and if it is connected it is told bye and its bricks go back to the queue uncharged.
  void banWorker(zmq::socket_t& router, const std::string& workerId, const std::string& why) {
    auto it = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
    if (it != peers_.end())
      for (uint64_t f : it->second.failedBricks) {
        Brick& b = bricks_[f];
        if (b.failedBy.erase(workerId) && b.failures > 0) --b.failures;
      }
    for (auto v = verifying_.begin(); v != verifying_.end();) {
      auto& ops = v->second.opinions;
      ops.erase(std::remove_if(ops.begin(), ops.end(), [&](const Opinion& o) { return o.workerId == workerId; }), ops.end());
      if (!ops.empty()) {
        ++v;
        continue;
      }
      bricks_[v->first].held = false;
      v = verifying_.erase(v);
    }
    if (bannedWorkers_.insert(workerId).second) {
      bannedWorkerOrder_.push_back(workerId);
      if (bannedWorkerOrder_.size() > kMaxBanned) {
        bannedWorkers_.erase(bannedWorkerOrder_.front());
        bannedWorkerOrder_.pop_front();
      }
    }
    if (it != peers_.end()) ban(router, it->first, why);
  }

  // ---- verification (--verify) -----------------------------------------------------------------

  // Whether `workerId` returned one of the results of `b` held now (it may not compute b again).
  bool holdsOpinion(const Brick& b, const std::string& workerId) const {
    if (!b.held) return false;
    auto v = verifying_.find(b.id);
    return v != verifying_.end() && std::any_of(v->second.opinions.begin(), v->second.opinions.end(),
                                                [&](const Opinion& o) { return o.workerId == workerId; });
  }

  // A brick whose result is held waits for another worker: back to the front of the queue (unless
  // a backup copy is still leased).
  void awaitAnotherWorker(Brick& b) {
    if (!b.holders.empty()) return;
    leased_.erase(b.id);
    b.phase = BrickPhase::Pending;
    b.backupIssued = b.leaseReissued = false;
    pending_.push_front(b.id);
  }

  // A checked result (CRC and codec verified): true when it is to be merged now, that is when it
  // has the same bytes as a held result of another worker (a majority of two: the workers whose
  // held results differ are convicted). Otherwise it is held, and the brick goes to a worker that
  // returned none of the held results; kMaxOpinions different results poison the brick.
  bool decide(zmq::socket_t& router, Arrival& a) {
    Brick& b = bricks_[a.brick];
    Verification& v = verifying_[a.brick];
    auto same = [&](const Opinion& o) {
      return o.bytes.size() == a.payload.size() && std::memcmp(o.bytes.data(), a.payload.data(), a.payload.size()) == 0;
    };
    for (const Opinion& o : v.opinions)
      if (o.workerId == a.workerId) {  // its own result again (a copy it was leased before): not a second opinion
        ++report_.duplicates;
        awaitAnotherWorker(b);
        return false;
      }
    auto match = std::find_if(v.opinions.begin(), v.opinions.end(), same);
    if (match != v.opinions.end()) {
      const std::string agreed = match->workerId + " and " + a.workerId;
      std::vector<std::string> outvoted;
      for (const Opinion& o : v.opinions)
        if (&o != &*match) outvoted.push_back(o.workerId);
      verifying_.erase(a.brick);
      b.held = false;
      for (const std::string& w : outvoted) convict(router, w, a.brick, agreed);
      return true;
    }
    std::string others;
    for (const Opinion& o : v.opinions) others += (others.empty() ? "" : ", ") + o.workerId;
    if (!v.opinions.empty()) {
      ++report_.verifyMismatches;
      spdlog::warn("brick {}: the result of worker {} differs from that of {}: another worker decides", a.brick,
                   a.workerId, others);
    }
    if (v.opinions.size() + 1 >= kMaxOpinions) {
      verifying_.erase(a.brick);
      b.held = false;
      leased_.erase(b.id);
      poison(b,
             "workers " + others + " and " + a.workerId + " returned " + std::to_string(kMaxOpinions) +
                 " different results: the computation is not deterministic across them (other builds or machines?)",
             std::to_string(kMaxOpinions) + " different results");
      return false;
    }
    v.opinions.push_back(Opinion{a.workerId, a.result, std::move(a.payload)});
    v.starved = false;
    b.held = true;
    awaitAnotherWorker(b);
    return false;
  }

  // Worker `workerId` was outvoted on `brick` (`agreed` returned the same other bytes): it lied
  // (or its machine computes differently). Banned; every brick it returned that was merged
  // unchecked is computed again by the others.
  void convict(zmq::socket_t& router, const std::string& workerId, uint64_t brick, const std::string& agreed) {
    ++report_.liarsBanned;
    banWorker(router, workerId, "its result for brick " + std::to_string(brick) + " differs from what workers " + agreed +
                                    " computed");
    const uint64_t redone = takeBackUnchecked(workerId, true);
    report_.bricksRedone += redone;
    spdlog::warn("worker {} banned: its result for brick {} differs from the one workers {} returned; {} brick(s) it "
                 "returned unchecked are computed again",
                 workerId, brick, agreed, redone);
  }

  // A worker under suspicion (its first refuted failure): the bricks of it merged unchecked are
  // computed again and checked, those that can still leave the output (a streamed slab stays).
  void recheckSuspect(const std::string& workerId) {
    const uint64_t n = takeBackUnchecked(workerId, false);
    report_.bricksRedone += n;
    if (n)
      spdlog::warn("worker {} is under suspicion (a failure of it was refuted): its {} brick(s) merged unchecked are "
                   "computed again and checked",
                   workerId, n);
  }

  // Uncommits the bricks merged unchecked from `workerId`'s results; `evenStreamed`: also those
  // whose slab was handed to the merge thread (tainted). Returns how many.
  uint64_t takeBackUnchecked(const std::string& workerId, bool evenStreamed) {
    auto w = workerIndex_.find(workerId);
    if (w == workerIndex_.end()) return 0;
    uint64_t n = 0;
    for (Brick& x : bricks_) {
      if (x.phase != BrickPhase::Done || x.verified || x.mergedFrom != w->second) continue;
      if (!evenStreamed && streaming_ && x.id / perSlab_ < slabsQueued_) continue;
      uncommit(x.id);
      if (!evenStreamed) x.verify = true;
      ++n;
    }
    return n;
  }

  // Checked bricks held while no connected worker can give them another result (every one
  // returned one of the held results): after FarmOptions::noWorkerTimeoutSec, a brick with one
  // result is merged unchecked (verification cannot run: reported), one with different results
  // is poisoned (no majority).
  void giveUpStarvedChecks(Clock::time_point now) {
    std::vector<uint64_t> due;
    for (auto& [id, v] : verifying_) {
      const Brick& b = bricks_[id];
      bool someone = b.phase != BrickPhase::Pending;
      for (auto p = peers_.begin(); !someone && p != peers_.end(); ++p)
        someone = !p->second.unreachable && !holdsOpinion(b, p->second.workerId);
      if (someone) {
        v.starved = false;
      } else if (!v.starved) {
        v.starved = true;
        v.starvedSince = now;
      } else if (now - v.starvedSince > std::chrono::seconds(opt_.noWorkerTimeoutSec)) {
        due.push_back(id);
      }
    }
    for (uint64_t id : due) {
      Brick& b = bricks_[id];
      Verification v = std::move(verifying_[id]);
      verifying_.erase(id);
      b.held = false;
      std::string who;
      for (const Opinion& o : v.opinions) who += (who.empty() ? "" : ", ") + o.workerId;
      if (v.opinions.size() > 1) {
        poison(b, "workers " + who + " returned different results and no other worker joined within " +
                      std::to_string(opt_.noWorkerTimeoutSec) + " s to decide",
               std::to_string(v.opinions.size()) + " different results");
        continue;
      }
      Opinion& o = v.opinions[0];
      Arrival a;
      a.brick = id;
      a.workerId = o.workerId;
      a.result = o.result;
      a.payload = std::move(o.bytes);
      if (!verifyPayload(a.payload.data(), a.payload.size(), b, a.out, a.kept, &a.error))
        throw std::logic_error("brick " + std::to_string(id) + ": a held result no longer verifies: " + a.error);
      countersOf(a.result, a.out);
      keep(a);
      ++report_.unverifiedBricks;
      if (report_.verifyUnavailable.empty()) {
        report_.verifyUnavailable = "no second worker was connected for " + std::to_string(opt_.noWorkerTimeoutSec) +
                                    " s: bricks merged unchecked";
        spdlog::warn("--verify cannot run: {} (brick {} first, from worker {})", report_.verifyUnavailable, id, who);
      }
      commit(id, std::move(a.out), a.workerId, true, std::move(a.kept));
    }
  }

  // A verified payload: appended to the journal if there is one, and for "sample" kept until
  // the merge: where the journal has it (the caller may hold the message as well, KeptBrick),
  // or (no journal) a copy in the arena. Safe on the decode threads at once.
  void journalAndKeep(uint64_t brick, const void* data, size_t size, uint32_t crc, KeptBrick& kept) {
    if (journal_) {
      const uint64_t at = journal_->add(brick, data, size, crc);
      if (op_ == Operation::Sample) kept.inJournal = true, kept.journalAt = at, kept.size = size, kept.crc = crc;
    } else if (op_ == Operation::Sample) {
      kept.payload = arena_.add(data, size);
    }
  }

  // Checks a payload (codec, inside the brick): "sample" is only scanned (its origins and tiles
  // to kept, its values left packed), the others are decoded into out.
  bool verifyPayload(const void* data, size_t size, const Brick& b, BrickOutput& out, KeptBrick& kept,
                     std::string* error) const {
    if (op_ == Operation::Sample) return scanBrick(data, size, kept.origins, kept.tiles, kept.leafAt, error) && insideBrick(kept, b);
    return decodePayload(op_, data, size, out, error) && insideBrick(out, b);
  }

  // "sample": every leaf and tile inside the brick, and no more leaves than it has.
  static bool insideBrick(const KeptBrick& k, const Brick& b) {
    for (auto& o : k.origins)
      for (int a = 0; a < 3; ++a)
        if (o[a] < b.lo[a] || o[a] >= b.hi[a]) return false;
    for (auto& t : k.tiles)
      for (int a = 0; a < 3; ++a)
        if (t.origin[a] < b.lo[a] || t.origin[a] >= b.hi[a]) return false;
    return k.origins.size() <= b.maxLeaves;
  }

  bool insideBrick(const BrickOutput& out, const Brick& b) const {
    if (op_ == Operation::Render)  // the brick's pixels, every one
      return out.tileLo == b.lo && out.tileHi == b.hi &&
             out.hits.size() == size_t(b.hi[0] - b.lo[0]) * size_t(b.hi[1] - b.lo[1]);
    if (op_ == Operation::Mesh) {
      // The piece of this brick: every vertex on an edge starting at a grid point of the
      // brick's cells, [lo, hi] (a cell's far corners included).
      if (out.piece.regionLo != b.lo) return false;
      for (const MeshVertex& v : out.piece.vertices) {
        auto k = edgeKeyParts(v.key);
        for (int a = 0; a < 3; ++a)
          if (k[size_t(a)] < b.lo[a] || k[size_t(a)] > b.hi[a]) return false;
      }
      return true;
    }
    return false;  // "sample" payloads are checked by scanning (verifyPayload)
  }

  void onFailed(const Envelope& e, const std::string& rid, Peer& p) {
    uint64_t id = e.failed().brick_id();
    if (id >= bricks_.size()) {
      ++report_.malformed;
      return;
    }
    Brick& b = bricks_[id];
    if (!holds(b, rid, p, "failure")) return;
    p.inflight.erase(id);
    b.holders.erase(rid);
    if (b.phase != BrickPhase::Leased || !b.holders.empty()) return;
    if (e.failed().handed_back()) {
      ++report_.handedBack;
      requeue(b, e.failed().error(), false);
    } else {
      spdlog::warn("brick {} failed on {}: {}", id, p.workerId, e.failed().error());
      ++p.failures;
      p.failedBricks.push_back(id);
      requeue(b, e.failed().error(), true, p.workerId);
    }
  }

  void poison(Brick& b, const std::string& why, const std::string& count) {
    if (std::exchange(b.held, false)) verifying_.erase(b.id);
    b.phase = BrickPhase::Poisoned;
    ++poisoned_;
    report_.poisoned.push_back(PoisonedBrick{b.id, b.lo, b.hi, why});
    spdlog::error("brick {} [{},{},{})-({},{},{}) poisoned after {}: {}", b.id, b.lo[0], b.lo[1], b.lo[2], b.hi[0],
                  b.hi[1], b.hi[2], count, why);
  }

  // Back to the queue; `counts`: a failure its holder (worker id `by`) reported: poisons when
  // kIndependentFailures workers failed it, or maxAttempts failures came from workers that had
  // no other to hand it to (mayTake).
  void requeue(Brick& b, const std::string& why, bool counts, const std::string& by = {}) {
    b.lastError = why;
    leased_.erase(b.id);
    if (counts) {
      ++b.failures;
      if (!by.empty()) b.failedBy.insert(by);
      b.lastFailure = Clock::now();
      if (b.failedBy.size() >= kIndependentFailures)
        return poison(b, why, std::to_string(b.failedBy.size()) + " workers failed it");
      if (b.failures >= opt_.maxAttempts) return poison(b, why, std::to_string(b.failures) + " failures");
    }
    ++report_.retries;
    b.phase = BrickPhase::Pending;
    b.backupIssued = b.leaseReissued = false;
    (b.suspect ? suspects_ : pending_).push_front(b.id);  // retry soon: it may be the last one
  }

  // A worker died computing b. Churn (workers that die anyway) must not poison it, a brick
  // that kills its workers must be: the first death only makes b suspect; a suspect is then
  // leased alone to a worker that has shown it is alive, preferably a fresh one that has
  // finished nothing yet (dispatch), so when that worker dies b is the common factor and the
  // death counts: maxAttempts distinct fresh workers, or twice as many workers in all, so
  // killed poison it. A worker that dies on its n-th brick whatever it is (churn) finishes a
  // suspect given to it fresh. Hello-and-vanish peers never count: they hold no suspect (they
  // never proved alive) and their first death is not charged.
  void onDeath(Brick& b, const Peer& p) {
    const std::string why = "worker " + p.workerId + " died while computing it";
    if (b.suspect && p.proven && p.inflight.size() == 1) {
      (p.finished == 0 ? b.killers : b.weakKillers).insert(p.workerId);
      if (int(b.killers.size()) >= opt_.maxAttempts ||
          int(b.killers.size() + b.weakKillers.size()) >= 2 * opt_.maxAttempts) {
        b.lastError = why;
        leased_.erase(b.id);
        return poison(b, why, std::to_string(b.killers.size() + b.weakKillers.size()) +
                                  " workers died computing it alone");
      }
    } else if (!b.suspect) {
      b.suspect = true;
      b.suspectSince = Clock::now();
      ++report_.suspectBricks;
    }
    requeue(b, why, false);
  }

  void dropPeer(const std::string& rid, Departure how) {
    auto it = peers_.find(rid);
    if (it == peers_.end()) return;
    const Peer& p = it->second;
    // The brick it was computing: its oldest lease (a worker computes its bricks in the order
    // they were leased; the younger ones were queued behind it).
    std::optional<uint64_t> computing;
    for (uint64_t id : p.inflight) {
      auto h = bricks_[id].holders.find(rid);
      if (h != bricks_[id].holders.end() && (!computing || h->second < bricks_[*computing].holders.at(rid)))
        computing = id;
    }
    for (uint64_t id : p.inflight) {
      Brick& b = bricks_[id];
      if (how == Departure::Dead && id == computing && b.phase == BrickPhase::Leased && b.holders.size() == 1)
        onDeath(b, p);
      else if (b.holders.erase(rid), b.phase == BrickPhase::Leased && b.holders.empty())
        requeue(b, how == Departure::Left ? "worker left" : "worker " + p.workerId + " dropped", false);
    }
    if (computing) bricks_[*computing].holders.erase(rid);
    peers_.erase(it);
  }

  void expireDeadPeers(Clock::time_point now) {
    std::vector<std::string> dead;
    for (auto& [rid, p] : peers_)
      if (now > p.expiry) dead.push_back(rid);
    for (auto& rid : dead) {
      ++report_.deadWorkers;
      spdlog::warn("worker {} silent past its liveness window: dead, its bricks go back to the queue",
                   peers_[rid].workerId);
      dropPeer(rid, Departure::Dead);
    }
  }

  // The median compute time of the merged bricks (lease and straggler timers). Every turn asks
  // for it; it is recomputed only once the sample has grown by an eighth (or is small), so the
  // whole job spends O(bricks) on it, not O(bricks) a turn.
  double medianBrickSeconds() {
    const size_t n = brickSeconds_.size();
    if (n != medianOf_ && (n < 64 || n >= medianOf_ + medianOf_ / 8)) {
      std::vector<double> v = brickSeconds_;
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      median_ = v[v.size() / 2];
      medianOf_ = n;
    }
    return median_;
  }

  // Leases past their deadline are issued once more to someone else (the first holder keeps
  // running: whichever result comes first is merged).
  void reissueOverdue(Clock::time_point now) {
    double lease = opt_.leaseSeconds > 0 ? opt_.leaseSeconds : std::max(30.0, 10 * medianBrickSeconds());
    for (uint64_t id : leased_) {
      Brick& b = bricks_[id];
      if (b.leaseReissued) continue;
      if (std::chrono::duration<double>(now - b.firstLease).count() > lease) {
        b.leaseReissued = true;
        ++report_.leaseReissues;
        reissue_.push_back(b.id);
      }
    }
  }

  void sendTask(zmq::socket_t& router, const std::string& rid, Peer& p, Brick& b, Clock::time_point now) {
    Envelope e;
    e.set_job_id(jobId_);
    Task* t = e.mutable_task();
    t->set_brick_id(b.id);
    t->set_attempt(++b.attempts);
    for (int a = 0; a < 3; ++a) {
      t->add_lo(b.lo[a]);
      t->add_hi(b.hi[a]);
    }
    if (!send(router, rid, e)) {
      // No route to the peer: its connection closed without a bye (it crashed or reconnected)
      // and its liveness window has not run out yet. dispatch() already took a pending brick
      // off pending_: put it back, or no one would lease it again and the job would never end
      // (the loop keeps waiting while the other workers heartbeat). A reissued or backup copy
      // stays leased to its other holders and goes back to the reissue queue (it was due).
      if (b.phase == BrickPhase::Pending) (b.suspect ? suspects_ : pending_).push_front(b.id);
      else reissue_.push_back(b.id);
      // The peer gets nothing more; it keeps its leases until its liveness window runs out
      // (then it is dead, expireDeadPeers) or it says hello again under a new connection (a
      // worker whose master was stalled reconnects: adoptReconnected), so one death is
      // judged one way, whichever way it is noticed first.
      if (!p.unreachable) spdlog::info("worker {} unreachable: no more bricks for it", p.workerId);
      p.unreachable = true;
      return;
    }
    if (b.phase != BrickPhase::Leased) b.firstLease = now;
    b.phase = BrickPhase::Leased;
    leased_.insert(b.id);
    b.holders[rid] = now;
    p.inflight.insert(b.id);
    p.everHeld.insert(b.id);
  }

  // Whether `cand` may be leased pending brick `b`. A worker that failed it gets it again only
  // when no other worker could take it (every peer failed it, or is unreachable), and only
  // after a wait: two liveness windows for a worker that has computed other bricks (its word
  // is credible: a brick that fails on the only worker is poisoned after maxAttempts), the
  // no-worker timeout for one that has computed none (a peer that fails everything must not
  // poison bricks before an honest worker joins).
  bool mayTake(const Peer& cand, const Brick& b, Clock::time_point now) const {
    if (holdsOpinion(b, cand.workerId)) return false;  // a checked brick goes to another worker, however long it waits
    if (!b.failedBy.count(cand.workerId)) return true;
    for (auto& [rid, q] : peers_)
      if (&q != &cand && !q.unreachable && !b.failedBy.count(q.workerId)) return false;
    const Clock::duration wait =
        cand.finished > 0 ? 2 * liveWindow() : Clock::duration(std::chrono::seconds(opt_.noWorkerTimeoutSec));
    return now - b.lastFailure > wait;
  }

  void dispatch(zmq::socket_t& router, Clock::time_point now) {
    // Cluster mode: give the expected workers a short grace period to join, so that the first
    // bricks spread over the whole farm instead of queuing on the earliest worker.
    if (opt_.expectWorkers > 0 && int(peers_.size()) < opt_.expectWorkers) {
      if (peers_.empty()) return;
      if (!firstJoin_) firstJoin_ = now;
      if (now - *firstJoin_ < std::chrono::seconds(5)) return;
    }
    // Peers in routing-id order: dispatch order never changes the output, only the schedule.
    std::vector<std::string> rids;
    for (auto& [rid, p] : peers_) rids.push_back(rid);
    auto holdsSuspect = [&](const Peer& p) {
      return std::any_of(p.inflight.begin(), p.inflight.end(), [&](uint64_t id) { return bricks_[id].suspect; });
    };
    // Takes the first brick of `queue` that `cand` may take (its phase `phase`), passing over at
    // most kMaxSkippedForPeer that it failed before (they stay at the front, in order).
    auto takeFrom = [&](std::deque<uint64_t>& queue, const Peer& cand, std::optional<uint64_t>& next) {
      std::vector<uint64_t> skipped;
      while (!queue.empty() && !next && skipped.size() < kMaxSkippedForPeer) {
        uint64_t id = queue.front();
        queue.pop_front();
        if (bricks_[id].phase != BrickPhase::Pending) continue;
        if (mayTake(cand, bricks_[id], now)) next = id;
        else skipped.push_back(id);
      }
      queue.insert(queue.begin(), skipped.begin(), skipped.end());
    };
    for (int round = 0; round < kCredit; ++round)
      for (auto& rid : rids) {
        auto it = peers_.find(rid);
        if (it == peers_.end() || it->second.unreachable || int(it->second.inflight.size()) > round ||
            holdsSuspect(it->second))
          continue;
        // A suspect brick goes only alone to a worker that has shown it is alive, a fresh one
        // unless it has waited two liveness windows for one (onDeath).
        const Peer& cand = it->second;
        const bool isolates = cand.proven && cand.inflight.empty() &&
                              (cand.finished == 0 || suspects_.empty() ||
                               now - bricks_[suspects_.front()].suspectSince > 2 * liveWindow());
        std::optional<uint64_t> next;
        if (isolates) takeFrom(suspects_, cand, next);
        std::vector<uint64_t> notHere;  // suspect copies due again, for an isolating worker
        while (!reissue_.empty() && !next) {
          uint64_t id = reissue_.front();
          reissue_.pop_front();
          if (bricks_[id].phase != BrickPhase::Leased || bricks_[id].holders.count(rid)) continue;
          if ((bricks_[id].suspect && !isolates) || bricks_[id].failedBy.count(cand.workerId) ||
              holdsOpinion(bricks_[id], cand.workerId))
            notHere.push_back(id);
          else next = id;
        }
        reissue_.insert(reissue_.begin(), notHere.begin(), notHere.end());
        if (!next) takeFrom(pending_, cand, next);
        if (!next) continue;
        sendTask(router, rid, it->second, bricks_[*next], now);
      }
    // Stragglers: nothing queued and a worker idle -> the oldest long-running brick, once more.
    if (!pending_.empty() || !suspects_.empty()) return;
    double threshold = std::max(1.0, 2 * medianBrickSeconds());
    for (auto& rid : rids) {
      auto it = peers_.find(rid);
      if (it == peers_.end() || it->second.unreachable || !it->second.inflight.empty()) continue;
      Brick* oldest = nullptr;
      for (uint64_t id : leased_)
        if (Brick& b = bricks_[id]; !b.backupIssued && !b.suspect && !b.holders.count(rid) &&
            !b.failedBy.count(it->second.workerId) && !holdsOpinion(b, it->second.workerId) &&
            std::chrono::duration<double>(now - b.firstLease).count() > threshold &&
            (!oldest || b.firstLease < oldest->firstLease))
          oldest = &b;
      if (!oldest) return;
      oldest->backupIssued = true;
      ++report_.stragglerReissues;
      spdlog::info("brick {} is a straggler: issued once more to {}", oldest->id, it->second.workerId);
      sendTask(router, rid, it->second, *oldest, now);
    }
  }

  // A kept payload's bytes: as received, in the arena, or read back from the journal into
  // `buffer` and checked against the CRC-32 it was verified with (the file is the master's own,
  // but what it merges must be exactly what it verified).
  std::string_view keptPayload(const KeptBrick& k, size_t brick, std::string& buffer) {
    if (k.received.held()) return k.received.bytes();
    if (!k.inJournal) return {k.payload.data(), k.payload.size()};
    buffer.resize(k.size);
    journal_->read(k.journalAt, buffer.data(), k.size);
    if (crc32Of(buffer.data(), buffer.size()) != k.crc)
      throw JournalIoError("journal " + journal_->path() + ": the record of brick " + std::to_string(brick) +
                           " changed after it was written (its CRC-32 no longer matches)");
    return buffer;
  }

  // ---- the merge of a sample ----------------------------------------------------------------
  // The bricks' leaves sorted by origin (as sample() sorts them) and their tiles, one slab of
  // bricks at a time: the bricks are planned x-slab by x-slab and the sort is by x first, so a
  // slab's leaves follow all the leaves of the slabs before it. A slab's leaf records are sorted
  // (slabRecords) and decoded in that order, in parallel, into consecutive blocks: the output
  // (mergeLeaves), or pieces that stay in the cache while the sink reads them (mergeSlabs). The
  // slab's payloads are then released, so the master holds the payloads or the output, not both.

  // The leaf records of the slab of bricks [first, last), sorted by origin, and its tiles
  // (appended to `tiles`). Payloads read back from the journal are kept in readBack (one string
  // a brick) while the records point into them. Runs on `threads`.
  void slabRecords(size_t first, size_t last, tbb::task_arena& threads, std::vector<LeafRecord>& sorted,
                   std::vector<std::string>& readBack, std::vector<Tile>& tiles) {
    std::vector<std::array<int32_t, 3>> origins;  // the slab's, brick by brick
    std::vector<size_t> start(1, 0), rank;         // rank[start[brick] + leaf]: the leaf's place in the slab
    for (size_t i = first; i < last; ++i) {
      origins.insert(origins.end(), kept_[i].origins.begin(), kept_[i].origins.end());
      start.push_back(origins.size());
      tiles.insert(tiles.end(), kept_[i].tiles.begin(), kept_[i].tiles.end());
    }
    sorted.resize(origins.size());
    readBack.resize(last - first);
    threads.execute([&] {
      rankByOrigin(origins, bricks_[first].lo, bricks_[last - 1].hi, rank);
      tbb::parallel_for(first, last, [&](size_t i) {
        const KeptBrick& k = kept_[i];
        if (k.origins.empty()) return;
        const std::string_view bytes = keptPayload(k, i, readBack[i - first]);
        const size_t* to = rank.data() + start[i - first];
        for (size_t l = 0; l < k.leafAt.size(); ++l) {
          const size_t end = l + 1 < k.leafAt.size() ? k.leafAt[l + 1] : bytes.size();
          sorted[to[l]] = LeafRecord{bytes.data() + k.leafAt[l], uint32_t(end - k.leafAt[l])};
        }
      });
    });
  }

  // After a slab's records were decoded: its payloads go (the arena unmaps emptied chunks).
  void releaseSlab(size_t first, size_t last, std::vector<std::string>& readBack) {
    for (size_t i = first; i < last; ++i) kept_[i] = KeptBrick{};
    readBack.clear();
  }

  // Streaming (FarmOptions::sampleSink): the loop hands the merge thread every slab whose bricks
  // are all merged, in slab order, as soon as they are (commit), so that the merge overlaps the
  // receiving of the next slabs instead of following the last brick.
  void queueCompleteSlabs() {
    size_t queued = slabsQueued_;
    while (queued < slabLeft_.size() && slabLeft_[queued] == 0) ++queued;
    if (queued == slabsQueued_) return;
    slabsQueued_ = queued;
    {
      std::lock_guard<std::mutex> lock(mergeMutex_);
      slabsReady_ = queued;
    }
    mergeWake_.notify_one();
  }

  // The merge thread: each slab handed over, in order, given to the sink: its tiles sorted, then
  // its leaves in pieces of kSinkPieceLeaves, decoded on its own threads (a piece each) into
  // buffers that are refilled; on every core once the loop is done (told to stop: the slabs
  // left are all there is to do). Stops when told to, once the slabs handed over are done.
  void mergeSlabs() {
    const SampleSink& sink = opt_.sampleSink;
    std::vector<std::vector<LeafBlock>> pieces(
        size_t(std::max({1, mergers_.max_concurrency(), allCores_.max_concurrency()})));
    for (auto& p : pieces) p.reserve(kSinkPieceLeaves);
    std::vector<LeafRecord> sorted;
    std::vector<std::string> readBack;
    std::vector<Tile> tiles;
    try {
      for (size_t next = 0;; ++next) {
        bool alone = false;
        {
          std::unique_lock<std::mutex> lock(mergeMutex_);
          mergeWake_.wait(lock, [&] { return slabsReady_ > next || mergeStop_; });
          if (slabsReady_ <= next) return;  // stopped, nothing more handed over
          alone = mergeStop_;
        }
        tbb::task_arena& threads = alone ? allCores_ : mergers_;
        const size_t inParallel = size_t(std::max(1, threads.max_concurrency()));
        const size_t first = next * perSlab_, last = std::min(bricks_.size(), first + perSlab_);
        tiles.clear();
        slabRecords(first, last, threads, sorted, readBack, tiles);
        std::vector<LeafBlock> noLeaves;
        sortByOrigin(noLeaves, tiles);
        if (!tiles.empty() && sink.tiles) sink.tiles(tiles);
        const size_t n = sorted.size();
        for (size_t round = 0; round < n; round += inParallel * kSinkPieceLeaves) {
          const size_t count = std::min(inParallel, (n - round + kSinkPieceLeaves - 1) / kSinkPieceLeaves);
          auto decodePiece = [&](size_t p) {
            const size_t from = round + p * kSinkPieceLeaves, to = std::min(n, from + kSinkPieceLeaves);
            pieces[p].resize(to - from);  // not zeroed (LeafBlock): decoded into
            decodeLeafRecords(sorted.data() + from, to - from, pieces[p].data());
          };
          if (count == 1) decodePiece(0);
          else threads.execute([&] { tbb::parallel_for(size_t(0), count, decodePiece); });
          for (size_t p = 0; p < count; ++p) sink.leaves(pieces[p]);
        }
        releaseSlab(first, last, readBack);
        streamedTiles_.insert(streamedTiles_.end(), tiles.begin(), tiles.end());
        std::lock_guard<std::mutex> lock(mergeMutex_);
        slabsStreamed_ = next + 1;
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mergeMutex_);
      mergeError_ = std::current_exception();
      mergeFailed_ = true;
    }
  }

  // Waits for the merge thread to finish the slabs handed over, and ends it.
  void stopMerger() {
    if (!merger_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mergeMutex_);
      mergeStop_ = true;
    }
    mergeWake_.notify_one();
    merger_.join();
  }

  // A failure of the merge thread (its sink threw, the journal could not be read) ends the job.
  void rethrowMergeError() {
    if (!mergeFailed_) return;
    std::lock_guard<std::mutex> lock(mergeMutex_);
    std::rethrow_exception(mergeError_);
  }

  // The merged sample in `result`. Streaming, the merge thread has handed every slab of a
  // complete job to the sink; of an incomplete one (a brick poisoned, or stopped) the slabs it
  // handed over (those before the first one not complete) and result.leaves holds the merged
  // leaves of the others. result.tiles holds every tile, sorted. Without a sink, the slabs are
  // decoded here into result.leaves, sized once.
  void mergeLeaves(SampleResult& result) {
    stopMerger();
    rethrowMergeError();
    result.tiles = std::move(streamedTiles_);
    size_t leaves = 0;
    const size_t firstKept = slabsStreamed_ * perSlab_;
    for (size_t i = firstKept; i < kept_.size(); ++i) leaves += kept_[i].origins.size();
    result.leaves.reserve(leaves);  // filled slab by slab: pages are touched as payloads are freed
    std::vector<Tile> tiles;
    std::vector<LeafRecord> sorted;
    std::vector<std::string> readBack;
    for (size_t first = firstKept; first < kept_.size(); first += perSlab_) {
      const size_t last = std::min(kept_.size(), first + perSlab_), at = result.leaves.size();
      slabRecords(first, last, decoders_, sorted, readBack, tiles);
      result.leaves.resize(at + sorted.size());  // not zeroed (LeafBlock): decoded into below, in ranges of a sink's piece
      decoders_.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, sorted.size(), kSinkPieceLeaves), [&](const tbb::blocked_range<size_t>& r) {
          decodeLeafRecords(sorted.data() + r.begin(), r.size(), result.leaves.data() + at + r.begin());
        });
      });
      releaseSlab(first, last, readBack);
    }
    std::vector<LeafBlock> noLeaves;
    sortByOrigin(noLeaves, tiles);
    result.tiles.insert(result.tiles.end(), tiles.begin(), tiles.end());  // after the streamed slabs' tiles
    kept_.clear();
  }

  FarmOutcome finish() {
    FarmOutcome o;
    // Bricks of a convicted worker were in slabs already streamed: the journal holds the job as
    // it must be; runJob merges it once more from there (a job that did not complete writes
    // nothing anyway, and its journal is right for --resume).
    report_.restreamed = streamTainted_ && done_ == bricks_.size() && !report_.interrupted;
    report_.operation = op_ == Operation::Mesh ? "mesh" : op_ == Operation::Render ? "render" : "sample";
    if (op_ == Operation::Render && done_ == bricks_.size()) {
      // The merge step of a render job: each tile's hits to their pixels (split-invariant, as
      // castRegion's regions give the whole image's hits).
      DepthImage& img = o.image;
      img.width = grid_.dims[0], img.height = grid_.dims[1];
      img.pixelStep = 2.0 * job_.render().half_width() / img.width;
      img.hits.assign(size_t(img.width) * size_t(img.height), RayHit{});
      for (const BrickOutput& out : outputs_) {
        const int w = out.tileHi[0] - out.tileLo[0];
        for (size_t i = 0; i < out.hits.size(); ++i) {
          const RayHit& h = out.hits[i];
          img.hits[size_t(out.tileLo[1] + int(i) / w) * size_t(img.width) + size_t(out.tileLo[0] + int(i) % w)] = h;
          report_.pixelsHit += h.kind != RayHit::kNone;
        }
      }
      outputs_.clear();
    }
    if (op_ == Operation::Mesh && done_ == bricks_.size()) {
      // The merge step of a mesh job: the pieces stitched by global edge key (split-invariant).
      // mergePiecesReleasing frees each piece as soon as it is stitched: the master holds about
      // one copy of the output mesh instead of three (the same mesh as mergePieces).
      std::vector<MeshPiece> pieces;
      pieces.reserve(outputs_.size());
      for (auto& out : outputs_) pieces.push_back(std::move(out.piece));
      outputs_.clear();
      o.mesh = mergePiecesReleasing(pieces, !allocatorPolicyApplied());
      report_.vertices = o.mesh.positions.size();
      report_.triangles = o.mesh.triangles.size();
    }
    o.result.grid = grid_;
    o.result.bandVoxels = job_.band();
    mergeLeaves(o.result);
    o.result.stats.pointEvals = report_.pointEvals;
    o.result.stats.intervalEvals = report_.intervalEvals;
    o.result.stats.nanValues = report_.nanValues;
    o.result.stats.domainErrors = report_.domainErrors;
    o.result.stats.denseEvals = uint64_t(grid_.dims[0]) * grid_.dims[1] * grid_.dims[2];
    report_.denseEvals = o.result.stats.denseEvals;
    report_.wallSeconds = std::chrono::duration<double>(Clock::now() - start_).count();
    report_.peakRssBytes = peakRssBytes();
    o.report = report_;
    return o;
  }

  JobSpec job_;
  FarmOptions opt_;
  uint64_t jobId_;
  GridSpec grid_;
  Operation op_;
  std::vector<Brick> bricks_;
  std::deque<uint64_t> pending_, reissue_;
  std::deque<uint64_t> suspects_;  // pending suspect bricks (onDeath), leased only alone
  std::set<std::string> banned_;   // routing ids that sent garbage
  std::deque<std::string> bannedOrder_;
  std::set<std::string> bannedWorkers_;  // worker ids banned for failing what others computed
  std::deque<std::string> bannedWorkerOrder_;
  std::map<std::string, std::string> aliases_;  // old routing id -> new, of reconnected workers
  std::vector<BrickOutput> outputs_;  // "mesh", "render": the merged bricks' results, by brick
  PayloadArena arena_;                // "sample": the kept payloads (before kept_ and arrivals_, which hold pieces of it)
  std::atomic<size_t> heldBytes_{0};  // "sample": bytes of received payloads kept (HeldPayload; before kept_ too)
  std::vector<KeptBrick> kept_;       // "sample": the merged bricks' payloads, by brick
  std::vector<Arrival> arrivals_;  // results received, not yet verified (verifyArrivals)
  size_t arrivalBytes_ = 0;
  tbb::task_arena decoders_;       // the decode threads (FarmOptions::decodeThreads)
  tbb::task_arena mergers_;        // streaming: the merge thread's decoders (as many)
  tbb::task_arena allCores_;       // streaming: the merge thread's, once the loop is done
  // Streaming (mergeSlabs): slabs of perSlab_ bricks, the bricks of each not merged yet, the
  // slabs handed to the merge thread (loop's count, and under mergeMutex_ the merge thread's),
  // the slabs it gave the sink and their tiles (read after it ends).
  bool streaming_ = false;
  size_t perSlab_ = 1;
  std::vector<size_t> slabLeft_;
  size_t slabsQueued_ = 0;
  std::thread merger_;
  std::mutex mergeMutex_;
  std::condition_variable mergeWake_;
  size_t slabsReady_ = 0, slabsStreamed_ = 0;
  bool mergeStop_ = false;
  std::exception_ptr mergeError_;
  std::atomic<bool> mergeFailed_{false};
  std::vector<Tile> streamedTiles_;
  std::map<std::string, Peer> peers_;
  // Verification (--verify): on (two workers can be compared), the fraction and seed of the
  // sample, the held results of the bricks under verification, the workers whose results were
  // merged (Brick::mergedFrom), the journal being replayed, a convicted worker's brick streamed.
  bool verifyOn_ = false;
  double fraction_ = 0;
  uint64_t seed_ = 0;
  std::map<uint64_t, Verification> verifying_;
  std::vector<std::string> workerNames_;
  std::map<std::string, uint32_t> workerIndex_;
  bool replaying_ = false;
  bool streamTainted_ = false;
  std::vector<double> brickSeconds_;
  double median_ = 0;    // medianBrickSeconds() of the first medianOf_ entries
  size_t medianOf_ = 0;
  std::set<uint64_t> leased_;  // bricks in phase Leased (timers scan only these)
  size_t payloadLimit_ = 0;
  size_t done_ = 0, poisoned_ = 0;
  FarmReport report_;
  std::unique_ptr<Journal> journal_;
  std::unique_ptr<LocalWorkers> retired_;  // the job's local workers, sent their bye
  std::unique_ptr<Progress> progress_;
  std::optional<Clock::time_point> firstJoin_;
  Clock::time_point start_;
};

}  // namespace

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
                 {"lease_reissues", leaseReissues}, {"refused", refused},
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
  nlohmann::json w = nlohmann::json::object();
  for (auto& [id, s] : perWorker)
    w[id] = {{"bricks", s.bricks},
             {"point_evals", s.pointEvals},
             {"compute_seconds", s.computeSeconds},
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
