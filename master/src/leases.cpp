// Leases: requeues, poisoning, deaths, re-issues of overdue bricks (docs/farm.md, "Faults").

#include <spdlog/spdlog.h>
#include <algorithm>

#include "master.h"

namespace frep::farm::detail {

void Master::poison(Brick& b, const std::string& why, const std::string& count) {
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
void Master::requeue(Brick& b, const std::string& why, bool counts, const std::string& by) {
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
void Master::onDeath(Brick& b, const Peer& p) {
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

void Master::dropPeer(const std::string& rid, Departure how) {
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

// The median compute time of the merged bricks (lease and straggler timers). Every turn asks
// for it; it is recomputed only once the sample has grown by an eighth (or is small), so the
// whole job spends O(bricks) on it, not O(bricks) a turn.
double Master::medianBrickSeconds() {
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
void Master::reissueOverdue(Clock::time_point now) {
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

// Whether `cand` may be leased pending brick `b`. A worker that failed it gets it again only
// when no other worker could take it (every peer failed it, or is unreachable), and only
// after a wait: two liveness windows for a worker that has computed other bricks (its word
// is credible: a brick that fails on the only worker is poisoned after maxAttempts), the
// no-worker timeout for one that has computed none (a peer that fails everything must not
// poison bricks before an honest worker joins).
bool Master::mayTake(const Peer& cand, const Brick& b, Clock::time_point now) const {
  if (holdsOpinion(b, cand.workerId)) return false;  // a checked brick goes to another worker, however long it waits
  if (!b.failedBy.count(cand.workerId)) return true;
  for (auto& [rid, q] : peers_)
    if (&q != &cand && !q.unreachable && !b.failedBy.count(q.workerId)) return false;
  const Clock::duration wait =
      cand.finished > 0 ? 2 * liveWindow() : Clock::duration(std::chrono::seconds(opt_.noWorkerTimeoutSec));
  return now - b.lastFailure > wait;
}

}  // namespace frep::farm::detail
