// The lease table (frep/farm/lease_table.h): moved out of the master's loop so that its rules
// (leases, deaths, failures, bans, re-issues, stalls) are tested with a made-up clock.
#include "frep/farm/lease_table.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace frep::farm {

LeaseTable::LeaseTable(size_t bricks, const LeasePolicy& policy, Hooks hooks)
    : policy_(policy), hooks_(std::move(hooks)), bricks_(bricks) {
  for (size_t i = 0; i < bricks; ++i) {
    bricks_[i].id = i;
    pending_.push_back(i);
  }
}

PeerLease& LeaseTable::join(const std::string& rid, const std::string& workerId, uint32_t threads, LeaseTime now) {
  PeerLease& p = peers_[rid];
  p.workerId = workerId;
  p.unreachable = false;  // a new connection
  p.threads = std::max(1u, threads);
  p.expiry = now + policy_.liveWindow;
  return p;
}

void LeaseTable::heard(PeerLease& p, LeaseTime now) {
  p.expiry = now + policy_.liveWindow;
  p.proven = true;
}

// The others' results went out on the connection the worker closed and may be lost, so those
// bricks go back to the queue (a late copy is a former holder's duplicate). Keeping them leased
// would hold the worker's credit for results that never come: with every worker reconnected,
// the job would wait for ever.
bool LeaseTable::adopt(const std::string& workerId, const std::string& rid, const std::set<uint64_t>& holding,
                       LeaseTime now, std::string* oldRid, size_t* lostCount) {
  auto old = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
  if (old == peers_.end()) return false;
  *oldRid = old->first;
  PeerLease moved = std::move(old->second);
  peers_.erase(old);
  std::vector<uint64_t> lost;
  for (uint64_t id : moved.inflight) {
    auto& h = bricks_[id].holders;
    auto node = h.extract(*oldRid);
    if (node && holding.count(id)) {
      node.key() = rid;
      h.insert(std::move(node));
    } else {
      lost.push_back(id);
    }
  }
  for (uint64_t id : lost) {
    moved.inflight.erase(id);
    BrickLease& b = bricks_[id];
    if (b.phase == BrickPhase::Leased && b.holders.empty())
      requeue(id, "its result was lost when worker " + workerId + " reconnected", false, now);
  }
  peers_[rid] = std::move(moved);
  *lostCount = lost.size();
  return true;
}

// A worker died computing b. Churn (workers that die anyway) must not poison it, a brick that
// kills its workers must be: the first death only makes b suspect; a suspect is then leased
// alone to a worker that has shown it is alive, preferably a fresh one that has finished nothing
// yet (dispatch), so when that worker dies b is the common factor and the death counts:
// maxAttempts distinct fresh workers, or twice as many workers in all, so killed poison it. A
// worker that dies on its n-th brick whatever it is (churn) finishes a suspect given to it
// fresh. Hello-and-vanish peers never count: they hold no suspect (they never proved alive) and
// their first death is not charged.
void LeaseTable::onDeath(BrickLease& b, const PeerLease& p, LeaseTime now) {
  const std::string why = "worker " + p.workerId + " died while computing it";
  if (b.suspect && p.proven && p.inflight.size() == 1) {
    (p.finished == 0 ? b.killers : b.weakKillers).insert(p.workerId);
    if (int(b.killers.size()) >= policy_.maxAttempts ||
        int(b.killers.size() + b.weakKillers.size()) >= 2 * policy_.maxAttempts) {
      b.lastError = why;
      leased_.erase(b.id);
      return poison(b.id, why,
                    std::to_string(b.killers.size() + b.weakKillers.size()) + " workers died computing it alone");
    }
  } else if (!b.suspect) {
    b.suspect = true;
    b.suspectSince = now;
    ++stats_.suspectBricks;
  }
  requeue(b.id, why, false, now);
}

void LeaseTable::drop(const std::string& rid, Departure how, LeaseTime now) {
  auto it = peers_.find(rid);
  if (it == peers_.end()) return;
  const PeerLease& p = it->second;
  // The brick it was computing: its oldest lease (a worker computes its bricks in the order
  // they were leased; the younger ones were queued behind it).
  std::optional<uint64_t> computing;
  for (uint64_t id : p.inflight) {
    auto h = bricks_[id].holders.find(rid);
    if (h != bricks_[id].holders.end() && (!computing || h->second < bricks_[*computing].holders.at(rid)))
      computing = id;
  }
  for (uint64_t id : p.inflight) {
    BrickLease& b = bricks_[id];
    if (how == Departure::Dead && id == computing && b.phase == BrickPhase::Leased && b.holders.size() == 1)
      onDeath(b, p, now);
    else if (b.holders.erase(rid), b.phase == BrickPhase::Leased && b.holders.empty())
      requeue(id, how == Departure::Left ? "worker left" : "worker " + p.workerId + " dropped", false, now);
  }
  if (computing) bricks_[*computing].holders.erase(rid);
  peers_.erase(it);
}

size_t LeaseTable::expire(LeaseTime now) {
  // After a stall, a hello sent during it may be read only now (ZeroMQ's I/O thread was stopped
  // too) and adopted with a fresh window while its worker, given up on that connection, sleeps.
  if (now <= stallGraceUntil_) return 0;
  std::vector<std::string> dead;
  for (auto& [rid, p] : peers_)
    if (now > p.expiry) dead.push_back(rid);
  for (auto& rid : dead) {
    ++stats_.deadWorkers;
    spdlog::warn("worker {} silent past its liveness window: dead, its bricks go back to the queue",
                 peers_[rid].workerId);
    drop(rid, Departure::Dead, now);
  }
  return dead.size();
}

// A turn is at most a poll (a quarter beat) and a bounded drain, so a gap longer than the
// liveness window means the master was deaf (SIGSTOP, swapping, a slow disk), not its peers
// silent (steady clock: wall-clock jumps do not count).
LeaseClock::duration LeaseTable::turn(LeaseTime last, LeaseTime now) {
  if (now - last <= policy_.liveWindow) return LeaseClock::duration::zero();
  ++stats_.masterStalls;
  const auto gap = now - last;
  // A worker's backoff after a silence of `gap` is at most gap + the first one (the earlier ones
  // and their windows add up to the current one minus the first), capped.
  const LeaseClock::duration sleep = std::min<LeaseClock::duration>(gap + kReconnectFirstBackoff, kReconnectMaxBackoff);
  stallGraceUntil_ = std::max(stallGraceUntil_, now + sleep + policy_.liveWindow);
  for (uint64_t id : leased_) bricks_[id].firstLease += gap;
  return gap;
}

Holding LeaseTable::holding(uint64_t id, const std::string& rid, const PeerLease& p) const {
  if (bricks_[id].holders.count(rid)) return Holding::Holder;
  return p.everHeld.count(id) ? Holding::FormerHolder : Holding::Stranger;
}

void LeaseTable::release(uint64_t id, const std::string& rid) {
  if (auto p = peers_.find(rid); p != peers_.end()) p->second.inflight.erase(id);
  bricks_[id].holders.erase(rid);
}

void LeaseTable::requeue(uint64_t id, const std::string& why, bool counts, LeaseTime now, const std::string& by) {
  BrickLease& b = bricks_[id];
  b.lastError = why;
  leased_.erase(b.id);
  if (counts) {
    ++b.failures;
    if (!by.empty()) b.failedBy.insert(by);
    b.lastFailure = now;
    if (b.failedBy.size() >= kIndependentFailures)
      return poison(id, why, std::to_string(b.failedBy.size()) + " workers failed it");
    if (b.failures >= policy_.maxAttempts) return poison(id, why, std::to_string(b.failures) + " failures");
  }
  ++stats_.retries;
  b.phase = BrickPhase::Pending;
  b.backupIssued = b.leaseReissued = false;
  (b.suspect ? suspects_ : pending_).push_front(b.id);  // retry soon: it may be the last one
}

void LeaseTable::poison(uint64_t id, const std::string& why, const std::string& count) {
  bricks_[id].phase = BrickPhase::Poisoned;
  leased_.erase(id);  // no timer, no straggler copy for it any more
  ++poisoned_;
  if (hooks_.poisoned) hooks_.poisoned(id, why, count);
}

void LeaseTable::complete(uint64_t id) {
  BrickLease& b = bricks_[id];
  b.phase = BrickPhase::Done;
  for (auto& [rid, t] : b.holders)  // cancelled copies no longer take a worker's credit
    if (auto p = peers_.find(rid); p != peers_.end()) p->second.inflight.erase(id);
  b.holders.clear();
  leased_.erase(id);
  ++done_;
}

void LeaseTable::credit(const std::string& workerId) {
  for (auto& [rid, p] : peers_)
    if (p.workerId == workerId) ++p.finished;
}

void LeaseTable::reopen(uint64_t id, bool queue) {
  BrickLease& b = bricks_[id];
  b.phase = BrickPhase::Pending;
  --done_;
  if (!queue) return;
  b.backupIssued = b.leaseReissued = false;
  pending_.push_front(id);
}

void LeaseTable::awaitAnother(uint64_t id) {
  BrickLease& b = bricks_[id];
  if (!b.holders.empty()) return;
  leased_.erase(b.id);
  b.phase = BrickPhase::Pending;
  b.backupIssued = b.leaseReissued = false;
  pending_.push_front(b.id);
}

// The median compute time of the merged bricks (lease and straggler timers). Every turn asks
// for it; it is recomputed only once the sample has grown by an eighth (or is small), so the
// whole job spends O(bricks) on it, not O(bricks) a turn.
double LeaseTable::medianBrickSeconds() {
  const size_t n = brickSeconds_.size();
  if (n != medianOf_ && (n < 64 || n >= medianOf_ + medianOf_ / 8)) {
    std::vector<double> v = brickSeconds_;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    median_ = v[v.size() / 2];
    medianOf_ = n;
  }
  return median_;
}

void LeaseTable::reissueOverdue(LeaseTime now) {
  double lease = policy_.leaseSeconds > 0 ? policy_.leaseSeconds : std::max(30.0, 10 * medianBrickSeconds());
  for (uint64_t id : leased_) {
    BrickLease& b = bricks_[id];
    if (b.leaseReissued) continue;
    if (std::chrono::duration<double>(now - b.firstLease).count() > lease) {
      b.leaseReissued = true;
      ++stats_.leaseReissues;
      reissue_.push_back(b.id);
    }
  }
}

// Whether `cand` may be leased pending brick `b`. A worker that failed it gets it again only
// when no other worker could take it (every peer failed it, or is unreachable), and only after
// a wait: two liveness windows for a worker that has computed other bricks (its word is
// credible: a brick that fails on the only worker is poisoned after maxAttempts), the no-worker
// timeout for one that has computed none (a peer that fails everything must not poison bricks
// before an honest worker joins).
bool LeaseTable::mayTake(const PeerLease& cand, const BrickLease& b, LeaseTime now) const {
  if (excluded(b.id, cand.workerId)) return false;  // a checked brick goes to another worker, however long it waits
  if (!b.failedBy.count(cand.workerId)) return true;
  for (auto& [rid, q] : peers_)
    if (&q != &cand && !q.unreachable && !b.failedBy.count(q.workerId)) return false;
  const LeaseClock::duration wait = cand.finished > 0 ? 2 * policy_.liveWindow : policy_.noWorkerTimeout;
  return now - b.lastFailure > wait;
}

void LeaseTable::lease(const std::string& rid, PeerLease& p, BrickLease& b, LeaseTime now, const Send& send) {
  if (!send(rid, b.id, ++b.attempts)) {
    // No route to the peer: its connection closed without a bye (it crashed or reconnected) and
    // its liveness window has not run out yet. dispatch() already took a pending brick off its
    // queue: put it back, or no one would lease it again and the job would never end (the loop
    // keeps waiting while the other workers heartbeat). A reissued or backup copy stays leased
    // to its other holders and goes back to the reissue queue (it was due).
    if (b.phase == BrickPhase::Pending) (b.suspect ? suspects_ : pending_).push_front(b.id);
    else reissue_.push_back(b.id);
    // The peer gets nothing more; it keeps its leases until its liveness window runs out (then
    // it is dead, expire) or it says hello again under a new connection (a worker whose master
    // was stalled reconnects: adopt), so one death is judged one way, whichever way it is
    // noticed first.
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

void LeaseTable::dispatch(LeaseTime now, const Send& send) {
  // Cluster mode: give the expected workers a short grace period to join, so that the first
  // bricks spread over the whole farm instead of queuing on the earliest worker.
  if (policy_.expectWorkers > 0 && int(peers_.size()) < policy_.expectWorkers) {
    if (peers_.empty()) return;
    if (!firstJoin_) firstJoin_ = now;
    if (now - *firstJoin_ < std::chrono::seconds(5)) return;
  }
  // Peers in routing-id order: dispatch order never changes the output, only the schedule.
  std::vector<std::string> rids;
  for (auto& [rid, p] : peers_) rids.push_back(rid);
  auto holdsSuspect = [&](const PeerLease& p) {
    return std::any_of(p.inflight.begin(), p.inflight.end(), [&](uint64_t id) { return bricks_[id].suspect; });
  };
  // Takes the first brick of `queue` that `cand` may take, passing over at most
  // kMaxSkippedForPeer that it failed before (they stay at the front, in order).
  auto takeFrom = [&](std::deque<uint64_t>& queue, const PeerLease& cand, std::optional<uint64_t>& next) {
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
  // With several peers, a peer's (round + 1)-th brick only while the queue holds `round` for
  // every peer: near the end of the job a worker's credit would keep bricks queued behind its
  // running one while another worker, done, waits with nothing (docs/farm.md, "Scaling").
  for (int round = 0; round < kCredit; ++round) {
    const size_t reachable =
        size_t(std::count_if(peers_.begin(), peers_.end(), [](auto& kv) { return !kv.second.unreachable; }));
    for (auto& rid : rids) {
      auto it = peers_.find(rid);
      if (it == peers_.end() || it->second.unreachable || int(it->second.inflight.size()) > round ||
          holdsSuspect(it->second))
        continue;
      if (round > 0 && reachable > 1 && reissue_.empty() && pending_.size() < size_t(round) * reachable) continue;
      // A suspect brick goes only alone to a worker that has shown it is alive, a fresh one
      // unless it has waited two liveness windows for one (onDeath).
      const PeerLease& cand = it->second;
      const bool isolates = cand.proven && cand.inflight.empty() &&
                            (cand.finished == 0 || suspects_.empty() ||
                             now - bricks_[suspects_.front()].suspectSince > 2 * policy_.liveWindow);
      std::optional<uint64_t> next;
      if (isolates) takeFrom(suspects_, cand, next);
      std::vector<uint64_t> notHere;  // suspect copies due again, for an isolating worker
      while (!reissue_.empty() && !next) {
        uint64_t id = reissue_.front();
        reissue_.pop_front();
        if (bricks_[id].phase != BrickPhase::Leased || bricks_[id].holders.count(rid)) continue;
        if ((bricks_[id].suspect && !isolates) || bricks_[id].failedBy.count(cand.workerId) ||
            excluded(id, cand.workerId))
          notHere.push_back(id);
        else next = id;
      }
      reissue_.insert(reissue_.begin(), notHere.begin(), notHere.end());
      if (!next) takeFrom(pending_, cand, next);
      if (!next) continue;
      lease(rid, it->second, bricks_[*next], now, send);
    }
  }
  // Nothing queued and a worker idle: a brick another worker holds queued behind the ones it is
  // computing, else the oldest long-running brick, once more (the first result cancels the
  // other copy, dropped if still queued).
  if (!pending_.empty() || !suspects_.empty()) return;
  double threshold = std::max(1.0, 2 * medianBrickSeconds());
  for (auto& rid : rids) {
    auto it = peers_.find(rid);
    if (it == peers_.end() || it->second.unreachable || !it->second.inflight.empty()) continue;
    if (BrickLease* queued = queuedElsewhere(rid, it->second)) {
      queued->backupIssued = true;
      ++stats_.queuedReissues;
      lease(rid, it->second, *queued, now, send);
      continue;
    }
    BrickLease* oldest = nullptr;
    for (uint64_t id : leased_)
      if (BrickLease& b = bricks_[id]; !b.backupIssued && !b.suspect && !b.holders.count(rid) &&
                                       !b.failedBy.count(it->second.workerId) && !excluded(id, it->second.workerId) &&
                                       std::chrono::duration<double>(now - b.firstLease).count() > threshold &&
                                       (!oldest || b.firstLease < oldest->firstLease))
        oldest = &b;
    if (!oldest) return;
    oldest->backupIssued = true;
    ++stats_.stragglerReissues;
    spdlog::info("brick {} is a straggler: issued once more to {}", oldest->id, it->second.workerId);
    lease(rid, it->second, *oldest, now, send);
  }
}

// A worker computes its bricks in the order they were leased to it, `threads` at a time, so
// those past its first `threads` by lease time wait in its queue. Near the end of a job the
// credit (kCredit) leaves such bricks behind a slow brick while another worker, done, idles:
// the last of them (the one that would start last) at any other peer goes to the idle one. The
// order by lease time is the master's view (ties by brick id); a brick that had started after
// all is computed twice, as a straggler's backup is.
BrickLease* LeaseTable::queuedElsewhere(const std::string& rid, const PeerLease& idle) {
  BrickLease* best = nullptr;
  std::pair<LeaseTime, uint64_t> bestOrder{};
  std::vector<std::pair<LeaseTime, uint64_t>> order;
  for (auto& [otherRid, other] : peers_) {
    if (otherRid == rid || other.inflight.size() <= other.threads) continue;
    order.clear();
    for (uint64_t id : other.inflight) {
      const BrickLease& b = bricks_[id];
      if (auto h = b.holders.find(otherRid); h != b.holders.end()) order.push_back({h->second, id});
    }
    std::sort(order.begin(), order.end());
    for (size_t k = other.threads; k < order.size(); ++k) {
      BrickLease& b = bricks_[order[k].second];
      if (b.phase != BrickPhase::Leased || b.backupIssued || b.suspect || b.holders.count(rid) ||
          b.failedBy.count(idle.workerId) || excluded(b.id, idle.workerId))
        continue;
      if (!best || bestOrder < order[k]) best = &b, bestOrder = order[k];
    }
  }
  return best;
}

// Honest workers are almost never refuted, and a model that fails everywhere refutes no one (no
// one computes its bricks).
LeaseTable::Refutation LeaseTable::refute(const std::string& workerId) {
  ++stats_.refutedFailures;
  Refutation r;
  auto it = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
  if (it == peers_.end()) return r;  // gone already
  PeerLease& p = it->second;
  r.known = true;
  r.first = ++p.refuted == 1;
  std::vector<uint64_t> others;
  for (auto& [rid, q] : peers_)
    if (&q != &p) others.push_back(q.refuted);
  std::sort(others.begin(), others.end());
  const uint64_t median = others.empty() ? 0 : others[(others.size() - 1) / 2];
  r.ban = p.refuted >= kBanAfterRefuted && p.refuted > 2 * median;
  r.refuted = p.refuted;
  r.failures = p.failures;
  return r;
}

void LeaseTable::forgetFailures(const std::string& workerId) {
  auto it = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
  if (it == peers_.end()) return;
  for (uint64_t f : it->second.failedBricks) {
    BrickLease& b = bricks_[f];
    if (b.failedBy.erase(workerId) && b.failures > 0) --b.failures;
  }
}

void LeaseTable::countFailure(PeerLease& p, uint64_t id) {
  ++p.failures;
  p.failedBricks.push_back(id);
}

}  // namespace frep::farm
