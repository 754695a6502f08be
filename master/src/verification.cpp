// --verify and refuted failures: second opinions, convictions, bans (docs/farm.md).

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cstring>

#include "frep/farm/crc32.h"
#include "master.h"

namespace frep::farm::detail {

// Worker `workerId` failed brick `id`, which another worker then computed. A worker refuted
// kBanAfterRefuted times and more than twice the lower median of the other peers' refuted
// failures fails what others compute: it is banned (told bye, its worker id refused, its
// failures no longer count against any brick). Honest workers are almost never refuted, and a
// model that fails everywhere refutes no one (no one computes its bricks). With --verify, a
// refuted worker is under suspicion: every result of it is checked from now on, and the
// bricks of it merged unchecked are computed again (recheckSuspect).
void Master::refute(zmq::socket_t& router, const std::string& workerId, uint64_t id) {
  const LeaseTable::Refutation r = leases_.refute(workerId);
  if (!r.known) return;  // gone already
  if (r.first && verifyOn_) recheckSuspect(workerId);
  if (!r.ban) return;
  spdlog::warn("worker {} banned: {} of its {} failures were computed by other workers (brick {} last)", workerId,
               r.refuted, r.failures, id);
  ++report_.failingPeersBanned;
  banWorker(router, workerId, "it failed " + std::to_string(r.refuted) + " bricks that other workers computed");
}

// Bans a worker id for the rest of the job: its failures and its held results no longer count
// against or for any brick, its worker id is refused when it says hello again (bounded list),
// and if it is connected it is told bye and its bricks go back to the queue uncharged.
void Master::banWorker(zmq::socket_t& router, const std::string& workerId, const std::string& why) {
  leases_.forgetFailures(workerId);
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
  auto it = std::find_if(peers().begin(), peers().end(), [&](auto& kv) { return kv.second.workerId == workerId; });
  if (it != peers().end()) ban(router, it->first, why);
}

// Whether `workerId` returned one of the results of `b` held now (it may not compute b again).
bool Master::holdsOpinion(const Brick& b, const std::string& workerId) const {
  if (!b.held) return false;
  auto v = verifying_.find(b.id);
  return v != verifying_.end() && std::any_of(v->second.opinions.begin(), v->second.opinions.end(),
                                              [&](const Opinion& o) { return o.workerId == workerId; });
}

// A brick whose result is held waits for another worker: back to the front of the queue (unless
// a backup copy is still leased).
void Master::awaitAnotherWorker(Brick& b) { leases_.awaitAnother(b.id); }

// A checked result (CRC and codec verified): true when it is to be merged now, that is when it
// has the same bytes as a held result of another worker (a majority of two: the workers whose
// held results differ are convicted). Otherwise it is held, and the brick goes to a worker that
// returned none of the held results; kMaxOpinions different results poison the brick.
bool Master::decide(zmq::socket_t& router, Arrival& a) {
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
    leases_.poison(b.id,
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
void Master::convict(zmq::socket_t& router, const std::string& workerId, uint64_t brick, const std::string& agreed) {
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
void Master::recheckSuspect(const std::string& workerId) {
  const uint64_t n = takeBackUnchecked(workerId, false);
  report_.bricksRedone += n;
  if (n)
    spdlog::warn("worker {} is under suspicion (a failure of it was refuted): its {} brick(s) merged unchecked are "
                 "computed again and checked",
                 workerId, n);
}

// Uncommits the bricks merged unchecked from `workerId`'s results; `evenStreamed`: also those
// whose slab was handed to the merge thread (tainted). Returns how many.
uint64_t Master::takeBackUnchecked(const std::string& workerId, bool evenStreamed) {
  auto w = workerIndex_.find(workerId);
  if (w == workerIndex_.end()) return 0;
  uint64_t n = 0;
  for (Brick& x : bricks_) {
    if (lease(x.id).phase != BrickPhase::Done || x.verified || x.mergedFrom != w->second) continue;
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
void Master::giveUpStarvedChecks(Clock::time_point now) {
  std::vector<uint64_t> due;
  for (auto& [id, v] : verifying_) {
    const Brick& b = bricks_[id];
    bool someone = lease(id).phase != BrickPhase::Pending;
    for (auto p = peers().begin(); !someone && p != peers().end(); ++p)
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
      leases_.poison(b.id, "workers " + who + " returned different results and no other worker joined within " +
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

}  // namespace frep::farm::detail
