// The master's lease table: which brick each worker holds, since when, who failed or died with
// which brick, and what to lease next (docs/farm.md, "Faults" and "Failing peers"). A plain
// object: no sockets and no clock of its own. Every call that depends on time takes `now`, so
// its tests drive it with a made-up clock instead of sleeping.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace frep::farm {

// The table never calls now(): it only compares the time points it is given.
using LeaseClock = std::chrono::steady_clock;
using LeaseTime = LeaseClock::time_point;

constexpr int kCredit = 4;  // bricks in flight per worker (hides latency)
// A brick is poisoned only when kIndependentFailures workers (distinct worker ids) failed it; a
// worker refuted kBanAfterRefuted times and more than twice the lower median of the others'
// refuted failures is banned (LeaseTable::refute).
constexpr size_t kIndependentFailures = 2;
constexpr uint64_t kBanAfterRefuted = 3;
constexpr size_t kMaxSkippedForPeer = 64;  // bricks a peer failed passed over per dispatch (bounded scan)
// A worker that hears nothing from its master for a live window reconnects after the first
// backoff, doubling it per silent attempt up to the last (worker.cpp); the master, waking from
// its own stall, gives its workers that long to come back (LeaseTable::turn).
constexpr std::chrono::milliseconds kReconnectFirstBackoff{1000};
constexpr std::chrono::milliseconds kReconnectMaxBackoff{32000};

enum class BrickPhase { Pending, Leased, Done, Poisoned };
enum class Departure { Left, Dead, Dropped };

struct LeasePolicy {
  int maxAttempts = 3;  // holder failures, or fresh workers dying with it alone, that poison a brick
  LeaseClock::duration liveWindow = std::chrono::seconds(3);  // heartbeat x liveness
  LeaseClock::duration noWorkerTimeout = std::chrono::seconds(120);
  double leaseSeconds = 0;  // re-issue a brick leased longer; 0: max(30 s, 10 x median)
  int expectWorkers = 0;    // dispatch waits up to 5 s after the first join for this many
};

// One brick's lease record.
struct BrickLease {
  uint64_t id = 0;
  BrickPhase phase = BrickPhase::Pending;
  int failures = 0;                // failed attempts reported by its holder (and corrupt results from it)
  std::set<std::string> failedBy;  // worker ids of those holders (not banned ones: forgetFailures)
  LeaseTime lastFailure{};
  // Worker deaths: the first death of a worker computing it makes it suspect; a suspect is
  // leased only alone to a worker that has shown it is alive, and each such worker that dies
  // with it counts; maxAttempts fresh killers (or twice as many in all) poison it.
  bool suspect = false;
  LeaseTime suspectSince{};
  std::set<std::string> killers;      // fresh workers (nothing finished) that died with it alone
  std::set<std::string> weakKillers;  // workers that had finished other bricks
  uint32_t attempts = 0;
  std::map<std::string, LeaseTime> holders;  // routing id -> lease start
  LeaseTime firstLease{};
  bool backupIssued = false, leaseReissued = false;
  std::string lastError;
};

// One connected worker, by routing id.
struct PeerLease {
  std::string workerId;
  uint32_t threads = 1;
  LeaseTime expiry{};
  std::set<uint64_t> inflight;
  std::set<uint64_t> everHeld;         // a later copy from a former holder is a duplicate, not foreign
  bool proven = false;                 // sent something after its hello (it lives past a task)
  bool unreachable = false;            // no route to it: no more tasks
  uint64_t finished = 0;               // bricks it computed that were merged
  uint64_t failures = 0;               // bricks it reported failed (not handed back)
  uint64_t refuted = 0;                // ... of which another worker then computed
  std::vector<uint64_t> failedBricks;  // the bricks it failed, to forget them if it is banned
};

// What the table counted (the master's report adds them).
struct LeaseStats {
  uint64_t retries = 0, deadWorkers = 0, stragglerReissues = 0, leaseReissues = 0;
  uint64_t queuedReissues = 0;  // bricks queued at a busy worker given to an idle one as well
  uint64_t suspectBricks = 0, masterStalls = 0, refutedFailures = 0;
};

// Whether a message about a brick comes from its holder.
enum class Holding { Holder, FormerHolder, Stranger };

class LeaseTable {
 public:
  // `poisoned`: called once a brick is poisoned (the table has marked it), with why and the
  // count that did it. `excluded`: whether a worker may not take a brick whatever the table
  // says (the master's --verify: it returned one of the brick's held results).
  struct Hooks {
    std::function<void(uint64_t brick, const std::string& why, const std::string& count)> poisoned;
    std::function<bool(uint64_t brick, const std::string& workerId)> excluded;
  };
  // `send` delivers a task; false: no route to the peer.
  using Send = std::function<bool(const std::string& rid, uint64_t brick, uint32_t attempt)>;

  LeaseTable() = default;
  LeaseTable(size_t bricks, const LeasePolicy& policy, Hooks hooks);

  size_t size() const { return bricks_.size(); }
  size_t done() const { return done_; }
  size_t poisonedCount() const { return poisoned_; }
  bool over() const { return done_ + poisoned_ >= bricks_.size(); }
  const BrickLease& brick(uint64_t id) const { return bricks_[id]; }
  const std::set<uint64_t>& leased() const { return leased_; }
  std::map<std::string, PeerLease>& peers() { return peers_; }
  const std::map<std::string, PeerLease>& peers() const { return peers_; }
  const LeaseStats& stats() const { return stats_; }

  // ---- peers ----
  // A hello from `rid`: a new peer, or a known one under a new connection.
  PeerLease& join(const std::string& rid, const std::string& workerId, uint32_t threads, LeaseTime now);
  // Any later message: alive until now + the live window, and proven.
  void heard(PeerLease& p, LeaseTime now);
  // A worker back under a new routing id keeps the leases of the bricks it still holds
  // (`holding`); the others go back to the queue. False if no peer has that worker id.
  bool adopt(const std::string& workerId, const std::string& rid, const std::set<uint64_t>& holding, LeaseTime now,
             std::string* oldRid, size_t* lost);
  // A peer gone: its bricks go back to the queue; for a dead one the brick it was computing
  // counts as a death (onDeath).
  void drop(const std::string& rid, Departure how, LeaseTime now);
  // Drops the peers silent past their window (counted dead); returns how many.
  size_t expire(LeaseTime now);
  // The loop's turn at `now` after the one at `last`: a gap longer than the live window is the
  // master's own stall, not its peers' silence: every lease timer moves on by it, and no peer,
  // nor one that comes back in the meantime, is counted dead until the end of the reconnect
  // backoff it may be sleeping in (as long as the gap, up to kReconnectMaxBackoff) plus a
  // window. Returns the gap if so (counted), else zero.
  LeaseClock::duration turn(LeaseTime last, LeaseTime now);

  // ---- leases ----
  // Whether `rid` holds the brick (a former holder's copy is a duplicate).
  Holding holding(uint64_t id, const std::string& rid, const PeerLease& p) const;
  // The holder answered (result or failure): its lease ends.
  void release(uint64_t id, const std::string& rid);
  // Back to the queue; `counts`: a failure its holder (worker id `by`) reported, which poisons
  // when kIndependentFailures workers failed it or maxAttempts failures were counted.
  void requeue(uint64_t id, const std::string& why, bool counts, LeaseTime now, const std::string& by = {});
  void poison(uint64_t id, const std::string& why, const std::string& count);
  // Merged: no longer leased; its holders' credit comes back. `merged` (worker id) finished it.
  void complete(uint64_t id);
  void credit(const std::string& workerId);
  // Taken back after it was merged: pending again; `queue` (not while replaying a journal,
  // where it is still queued) puts it at the front of the queue.
  void reopen(uint64_t id, bool queue);
  // A brick whose result is held for a second opinion: back to the front of the queue, unless
  // a copy is still leased.
  void awaitAnother(uint64_t id);
  // Leases past their deadline are due once more (the first holder keeps running).
  void reissueOverdue(LeaseTime now);
  // Leases queued bricks to the peers with credit (kCredit rounds, in routing-id order), then
  // an idle worker gets a brick queued at another once more, or the oldest straggler.
  void dispatch(LeaseTime now, const Send& send);
  void addBrickSeconds(double seconds) { brickSeconds_.push_back(seconds); }
  double medianBrickSeconds();

  // ---- failing peers ----
  struct Refutation {
    bool known = false;  // the worker is connected
    bool first = false;  // its first refuted failure
    bool ban = false;    // refuted kBanAfterRefuted times and more than twice the others' median
    uint64_t refuted = 0, failures = 0;
  };
  // Worker `workerId` failed a brick another worker then computed.
  Refutation refute(const std::string& workerId);
  // A banned worker's failures no longer count against any brick.
  void forgetFailures(const std::string& workerId);
  // The peer's failure of brick `id` (not handed back): counted against it and the brick.
  void countFailure(PeerLease& p, uint64_t id);

 private:
  void onDeath(BrickLease& b, const PeerLease& p, LeaseTime now);
  bool mayTake(const PeerLease& cand, const BrickLease& b, LeaseTime now) const;
  bool excluded(uint64_t id, const std::string& workerId) const {
    return hooks_.excluded && hooks_.excluded(id, workerId);
  }
  void lease(const std::string& rid, PeerLease& p, BrickLease& b, LeaseTime now, const Send& send);
  BrickLease* queuedElsewhere(const std::string& rid, const PeerLease& idle);

  LeasePolicy policy_;
  Hooks hooks_;
  std::vector<BrickLease> bricks_;
  std::deque<uint64_t> pending_, reissue_;
  std::deque<uint64_t> suspects_;  // pending suspect bricks (onDeath), leased only alone
  std::set<uint64_t> leased_;      // bricks in phase Leased (timers scan only these)
  std::map<std::string, PeerLease> peers_;
  std::vector<double> brickSeconds_;
  double median_ = 0;  // medianBrickSeconds() of the first medianOf_ entries
  size_t medianOf_ = 0;
  size_t done_ = 0, poisoned_ = 0;
  std::optional<LeaseTime> firstJoin_;
  // After the master's own stall, nobody is counted dead before this (turn): a worker's stale
  // hello may be read only after the stall is seen, then the worker sleeps its backoff.
  LeaseTime stallGraceUntil_{};
  LeaseStats stats_;
};

}  // namespace frep::farm
