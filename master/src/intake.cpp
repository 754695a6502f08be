// Results and failures from the workers: verified, decoded, journaled, judged (master.h).

#include <spdlog/spdlog.h>
#include <cmath>

#include <tbb/parallel_for.h>

#include "frep/farm/crc32.h"
#include "master.h"

namespace frep::farm::detail {

void Master::onResult(zmq::socket_t& router, Incoming& in, Peer& p) {
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
  leases_.release(id, in.routingId);
  if (lease(id).phase == BrickPhase::Done || lease(id).phase == BrickPhase::Poisoned) {
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
void Master::verifyArrivals(zmq::socket_t& router) {
  if (arrivals_.empty()) return;
  // The first unchecked copy of a brick in the batch is journaled here, before the judge merges
  // it (a copy not merged after all is revoked there); later copies and checked results (merged
  // only once another worker agrees) are journaled by the judge if it merges them.
  std::set<uint64_t> first;
  for (Arrival& a : arrivals_) a.journaled = !a.check && first.insert(a.brick).second;
  // Groups of consecutive arrivals up to kJournalGroupBytes, each checked then journaled in one
  // call while its payloads are still in the core's cache: journaling the whole batch after
  // checking it all made the kernel's copy into the page cache read them from memory again.
  std::vector<size_t> groups(1, 0);
  for (size_t i = 0, bytes = 0; i < arrivals_.size(); ++i) {
    bytes += arrivals_[i].payload.size();
    if (bytes >= kJournalGroupBytes || i + 1 == arrivals_.size()) groups.push_back(i + 1), bytes = 0;
  }
  decoders_.execute([&] {
    tbb::parallel_for(size_t(0), groups.size() - 1, [&](size_t g) {
      for (size_t i = groups[g]; i < groups[g + 1]; ++i) {
        Arrival& a = arrivals_[i];
        const void* data = a.payload.data();
        const size_t size = a.payload.size();
        const uint32_t crc = a.result.payload_crc32();
        a.ok = crc32Of(data, size) == crc && verifyPayload(data, size, bricks_[a.brick], a.out, a.kept, &a.error);
        a.journaled = a.journaled && a.ok;
        if (a.journaled && !journal_) keep(a);  // into the arena; with a journal, below
        // Not held: freed now, the next message's buffer reuses its memory.
        if (!a.ok || (a.journaled && !journal_)) a.payload = zmq::message_t();
      }
      if (journal_) journalArrivals(groups[g], groups[g + 1]);
    });
  });
  for (Arrival& a : arrivals_) judge(router, a);
  arrivals_.clear();
  arrivalBytes_ = 0;
}

// Arrivals [from, to)'s verified first copies, journaled together (Journal::addAll: one system
// call where each took one) before any of them is judged, and kept for the merge as keep()
// keeps one. Safe on the decode threads at once (other ranges).
void Master::journalArrivals(size_t from, size_t to) {
  std::vector<Journal::Record> records;
  for (size_t i = from; i < to; ++i)
    if (const Arrival& a = arrivals_[i]; a.journaled)
      records.push_back({a.brick, a.payload.data(), a.payload.size(), a.result.payload_crc32(), 0});
  if (records.empty()) return;
  journal_->addAll(records.data(), records.size());
  size_t r = 0;
  for (size_t i = from; i < to; ++i) {
    Arrival& a = arrivals_[i];
    if (!a.journaled) continue;
    const Journal::Record& rec = records[r++];
    if (op_ == Operation::Sample) {
      a.kept.inJournal = true, a.kept.journalAt = rec.at, a.kept.size = rec.size, a.kept.crc = rec.crc;
      a.kept.received = HeldPayload::take(a.payload, heldBytes_, opt_.heldPayloadBytes);
    }
    a.payload = zmq::message_t();  // not held: freed now, the next message's buffer reuses its memory
  }
}

// A copy journaled (verifyArrivals) that is not merged: void in the journal, so that a resume
// does not merge it either. Only the batch's first copy of a brick is journaled there, so the
// brick is not merged from another record now.
void Master::revokeUnmerged(const Arrival& a) {
  if (!a.journaled || !journal_) return;
  const uint64_t v = a.brick;
  journal_->add(kJournalRevoke, &v, 8, crc32Of(&v, 8));
}

// A result's counters (the worker's word: only the payload is checked) into its output.
void Master::countersOf(const Result& r, BrickOutput& out) {
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

void Master::judge(zmq::socket_t& router, Arrival& a) {
  Brick& b = bricks_[a.brick];
  const uint64_t id = a.brick;
  if (banned_.count(a.routingId) || bannedWorkers_.count(a.workerId)) {
    // Its sender was dropped (garbage, or convicted) after sending it (an earlier result of
    // this batch): ignored, as a message received after the ban would have been; the brick
    // goes back.
    revokeUnmerged(a);
    if (lease(id).phase == BrickPhase::Leased && lease(id).holders.empty())
      requeue(b, "worker " + a.workerId + " dropped", false);
    return;
  }
  if (lease(id).phase == BrickPhase::Done || lease(id).phase == BrickPhase::Poisoned) {
    ++report_.duplicates;  // another copy of this batch was merged first
    if (lease(id).phase == BrickPhase::Poisoned) revokeUnmerged(a);
    return;
  }
  if (!a.ok) {
    // The holder's own brick came back corrupt: it counts as a failure of the brick (a brick
    // that breaks every worker's encoder is poisoned like one that fails), and the peer,
    // which sent garbage, is dropped.
    ++report_.malformed;
    std::string why = "corrupt result from " + a.workerId + ": " + (a.error.empty() ? "crc or bounds" : a.error);
    spdlog::warn("dropped a {}", why);
    if (lease(id).holders.empty()) requeue(b, why, true, a.workerId);
    ban(router, a.routingId, "corrupt result for brick " + std::to_string(id));
    return;
  }
  const Result& r = a.result;
  BrickOutput& out = a.out;
  countersOf(r, out);
  report_.perWorker[a.workerId].computeSeconds += r.compute_seconds();
  leases_.addBrickSeconds(r.compute_seconds());
  auto sender = peers().find(a.routingId);
  if (!a.check && sender != peers().end() && needsCheck(b, sender->second)) {
    // The brick must be checked since this copy arrived (its sender came under suspicion, or
    // another copy of the batch was held), and this copy was journaled unchecked and its bytes
    // let go: taken back (uncharged); the brick is computed again and checked.
    revokeUnmerged(a);
    b.verify = true;
    if (b.held) awaitAnotherWorker(b);
    else if (lease(id).holders.empty()) requeue(b, "it is to be checked: computed again", false);
    return;
  }
  if (a.check && !decide(router, a)) return;  // held until another worker agrees (or poisoned)
  if (!a.journaled && (journal_ || op_ == Operation::Sample)) keep(a);  // checked, or a later copy of the batch
  // Other holders (straggler backups) may drop the brick.
  for (auto& [rid, t] : lease(id).holders) {
    Envelope c;
    c.mutable_cancel()->set_brick_id(id);
    send(router, rid, c);
  }
  commit(id, std::move(out), a.workerId, true, std::move(a.kept), a.check);
  // Every other worker that failed this brick was refuted: the computation is deterministic.
  for (const std::string& w : std::vector<std::string>(lease(id).failedBy.begin(), lease(id).failedBy.end()))
    if (w != a.workerId) refute(router, w, id);
}

// A verified payload: appended to the journal if there is one, and for "sample" kept until
// the merge: where the journal has it (the caller may hold the message as well, KeptBrick),
// or (no journal) a copy in the arena. Safe on the decode threads at once.
void Master::journalAndKeep(uint64_t brick, const void* data, size_t size, uint32_t crc, KeptBrick& kept) {
  if (journal_) {
    const uint64_t at = journal_->add(brick, data, size, crc);
    if (op_ == Operation::Sample) kept.inJournal = true, kept.journalAt = at, kept.size = size, kept.crc = crc;
  } else if (op_ == Operation::Sample) {
    kept.payload = arena_.add(data, size);
  }
}

// Checks a payload (codec, inside the brick): "sample" is only scanned (its origins and tiles
// to kept, its values left packed), the others are decoded into out.
bool Master::verifyPayload(const void* data, size_t size, const Brick& b, BrickOutput& out, KeptBrick& kept,
                   std::string* error) const {
  if (op_ == Operation::Sample) return scanBrick(data, size, kept.origins, kept.tiles, kept.leafAt, error) && insideBrick(kept, b);
  return decodePayload(op_, data, size, out, error) && insideBrick(out, b);
}

// "sample": every leaf and tile inside the brick, and no more leaves than it has.
bool Master::insideBrick(const KeptBrick& k, const Brick& b) {
  for (auto& o : k.origins)
    for (int a = 0; a < 3; ++a)
      if (o[a] < b.lo[a] || o[a] >= b.hi[a]) return false;
  for (auto& t : k.tiles)
    for (int a = 0; a < 3; ++a)
      if (t.origin[a] < b.lo[a] || t.origin[a] >= b.hi[a]) return false;
  return k.origins.size() <= b.maxLeaves;
}

bool Master::insideBrick(const BrickOutput& out, const Brick& b) const {
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

void Master::onFailed(const Envelope& e, const std::string& rid, Peer& p) {
  uint64_t id = e.failed().brick_id();
  if (id >= bricks_.size()) {
    ++report_.malformed;
    return;
  }
  Brick& b = bricks_[id];
  if (!holds(b, rid, p, "failure")) return;
  leases_.release(id, rid);
  if (lease(id).phase != BrickPhase::Leased || !lease(id).holders.empty()) return;
  if (e.failed().handed_back()) {
    ++report_.handedBack;
    requeue(b, e.failed().error(), false);
  } else {
    spdlog::warn("brick {} failed on {}: {}", id, p.workerId, e.failed().error());
    leases_.countFailure(p, id);
    requeue(b, e.failed().error(), true, p.workerId);
  }
}

}  // namespace frep::farm::detail
