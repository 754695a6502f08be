// The master's state (internal to master/): one job's bricks, peers, verification and merge,
// and the Master that runs them. Its methods live by concern: master.cpp (the job: plan, commit,
// in-process), loop.cpp (the scheduling loop and the peers), intake.cpp (results and failures),
// verification.cpp (--verify, refuted failures, bans), leases.cpp (leases, deaths, re-issues),
// merge.cpp (the merge of the bricks' outputs).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>
#include <zmq.hpp>

#include <tbb/task_arena.h>

#include "frep/farm/brick_codec.h"
#include "frep/farm/job.h"
#include "frep/farm/lease_table.h"
#include "frep/master/farm_master.h"
#include "frep/master/journal.h"
#include "frep/master/leaf_records.h"
#include "frep/master/local_workers.h"
#include "frep/master/payload_arena.h"
#include "frep/master/progress.h"
#include "frep/net/wire.h"

namespace frep::farm::detail {

using Clock = std::chrono::steady_clock;
// Set by SIGTERM/SIGINT/SIGHUP while a job runs (master.cpp): the job stops, its journal flushed.
extern std::atomic<bool> gStop;

constexpr size_t kMaxEnvelopeBytes = 1 << 20;  // a task or result header is a few KB at most
// Hostile peers (docs/farm.md, "Threat model"): an un-welcomed routing id may send only a
// hello, checked before parsing; garbage bans its routing id. The ban list and the welcomed
// workers are bounded so strangers cannot grow the master's state without limit.
constexpr size_t kMaxHelloBytes = 64 << 10;
constexpr size_t kMaxBanned = 1024;     // banned routing ids remembered (oldest forgotten)
constexpr size_t kMaxPeers = 4096;      // welcomed workers at once; a hello beyond is refused
constexpr size_t kMaxAliases = 4096;    // routing ids of workers that reconnected
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
// A batch is checked and journaled in groups of about this many payload bytes (one system call
// a group; a group stays in a core's 2 MiB L2 cache between its check and its journaling).
constexpr size_t kJournalGroupBytes = 1 << 20;

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

// A brick of the job as the master sees it (its lease is LeaseTable's BrickLease).
struct Brick {
  uint64_t id = 0;
  std::array<int32_t, 3> lo{}, hi{};
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

using Peer = PeerLease;

class Master {
 public:
  Master(const JobSpec& job, const FarmOptions& opt);

  ~Master() { stopMerger(); }

  FarmOutcome run();

 private:
  void setUpVerification(std::optional<uint64_t> journalSeed);

  int localWorkerCount() const {
    return opt_.workers > 0 ? opt_.workers : int(std::max(1u, std::thread::hardware_concurrency()));
  }

  uint32_t workerIndex(const std::string& workerId);

  void plan();

  void commit(uint64_t id, BrickOutput&& out, const std::string& who, bool computed, KeptBrick&& kept = {},
              bool verified = false);

  void uncommit(uint64_t id);

  void runInProcess();

  // ---- the farm -------------------------------------------------------------------------

  void runFarm();

  void handle(zmq::socket_t& router, Incoming& in, const std::string& err);

  bool adoptReconnected(const std::string& workerId, const std::string& rid, const Hello& hello);

  // `rid` by value: it may be the key of the peer entry that ban erases (banWorker).
  void ban(zmq::socket_t& router, std::string rid, const std::string& why);

  size_t payloadLimit() const { return payloadLimit_; }
  Clock::duration liveWindow() const { return std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness); }

  static std::string printable(const std::string& rid);

  bool holds(const Brick& b, const std::string& rid, const Peer& p, const char* what);
  std::map<std::string, Peer>& peers() { return leases_.peers(); }

  void onResult(zmq::socket_t& router, Incoming& in, Peer& p);
  void noteWorkerTime(const std::string& workerId, const Result& r);
  void reportWorkerTime();
  // By worker id: the time counters of every result received (WorkerShare's; they go to the
  // report for the workers that have a brick merged), and when the last one came in.
  std::map<std::string, WorkerShare> workerTime_;
  std::map<std::string, Clock::time_point> lastResultAt_;

  void verifyArrivals(zmq::socket_t& router);
  void journalArrivals(size_t from, size_t to);

  // Journals a verified payload and keeps it for the merge ("sample": the message itself while
  // the held bytes allow, with a journal; a copy in the arena without one).
  void keep(Arrival& a) {
    journalAndKeep(a.brick, a.payload.data(), a.payload.size(), a.result.payload_crc32(), a.kept);
    if (a.kept.inJournal) a.kept.received = HeldPayload::take(a.payload, heldBytes_, opt_.heldPayloadBytes);
  }

  void revokeUnmerged(const Arrival& a);

  // Whether a result of `b` from `p` is merged only once another worker returns the same bytes:
  // with --verify, a brick of the sample, one already held, or any brick of a peer under
  // suspicion (failures of it that other workers refuted).
  bool needsCheck(const Brick& b, const Peer& p) const { return verifyOn_ && (b.verify || b.held || p.refuted > 0); }

  static void countersOf(const Result& r, BrickOutput& out);

  void judge(zmq::socket_t& router, Arrival& a);

  void refute(zmq::socket_t& router, const std::string& workerId, uint64_t id);

  void banWorker(zmq::socket_t& router, const std::string& workerId, const std::string& why);

  // ---- verification (--verify) -----------------------------------------------------------------

  bool holdsOpinion(const Brick& b, const std::string& workerId) const;

  void awaitAnotherWorker(Brick& b);

  bool decide(zmq::socket_t& router, Arrival& a);

  void convict(zmq::socket_t& router, const std::string& workerId, uint64_t brick, const std::string& agreed);

  void recheckSuspect(const std::string& workerId);

  uint64_t takeBackUnchecked(const std::string& workerId, bool evenStreamed);

  void giveUpStarvedChecks(Clock::time_point now);

  void journalAndKeep(uint64_t brick, const void* data, size_t size, uint32_t crc, KeptBrick& kept);

  bool verifyPayload(const void* data, size_t size, const Brick& b, BrickOutput& out, KeptBrick& kept,
                     std::string* error) const;

  static bool insideBrick(const KeptBrick& k, const Brick& b);

  bool insideBrick(const BrickOutput& out, const Brick& b) const;

  void onFailed(const Envelope& e, const std::string& rid, Peer& p);

  // The lease table's (leases_): a brick poisoned, and what the master keeps of it.
  void onPoisoned(uint64_t id, const std::string& why, const std::string& count);
  const BrickLease& lease(uint64_t id) const { return leases_.brick(id); }
  LeasePolicy leasePolicy() const;
  void requeue(const Brick& b, const std::string& why, bool counts, const std::string& by = {}) {
    leases_.requeue(b.id, why, counts, Clock::now(), by);
  }

  bool sendTask(zmq::socket_t& router, const std::string& rid, uint64_t id, uint32_t attempt);

  // A buffer for a payload read back from the journal, reused from slab to slab: not zeroed
  // when it grows (std::string's resize wrote each 150 kB once more) and not faulted in anew.
  struct ReadBack {
    std::unique_ptr<char[]> bytes;
    size_t capacity = 0;
    char* room(size_t size) {
      if (size > capacity) bytes.reset(new char[capacity = size + size / 8]);
      return bytes.get();
    }
  };
  std::string_view keptPayload(const KeptBrick& k, size_t brick, ReadBack& buffer);

  // ---- the merge of a sample ----------------------------------------------------------------
  // The bricks' leaves sorted by origin (as sample() sorts them) and their tiles, one slab of
  // bricks at a time: the bricks are planned x-slab by x-slab and the sort is by x first, so a
  // slab's leaves follow all the leaves of the slabs before it. A slab's leaf records are sorted
  // (slabRecords) and decoded in that order, in parallel, into consecutive blocks: the output
  // (mergeLeaves), or pieces that stay in the cache while the sink reads them (mergeSlabs). The
  // slab's payloads are then released, so the master holds the payloads or the output, not both.

  void slabRecords(size_t first, size_t last, tbb::task_arena& threads, std::vector<LeafRecord>& sorted,
                   std::vector<ReadBack>& readBack, std::vector<Tile>& tiles);

  void releaseSlab(size_t first, size_t last);

  void queueCompleteSlabs();

  void mergeSlabs();

  void stopMerger();

  void rethrowMergeError();

  void mergeLeaves(SampleResult& result);

  FarmOutcome finish();

  JobSpec job_;
  FarmOptions opt_;
  uint64_t jobId_;
  GridSpec grid_;
  Operation op_;
  std::vector<Brick> bricks_;
  LeaseTable leases_;  // the bricks' leases and the peers (leases.cpp)
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
  size_t payloadLimit_ = 0;
  FarmReport report_;
  std::unique_ptr<Journal> journal_;
  std::unique_ptr<LocalWorkers> retired_;  // the job's local workers, sent their bye
  std::unique_ptr<Progress> progress_;
  Clock::time_point start_;
};

}  // namespace frep::farm::detail
