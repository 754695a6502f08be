// The master's side of the lease table (frep/farm/lease_table.h): its policy from the options,
// the tasks it sends, and what a poisoned brick leaves in the report.

#include <spdlog/spdlog.h>

#include "master.h"

namespace frep::farm::detail {

LeasePolicy Master::leasePolicy() const {
  LeasePolicy p;
  p.maxAttempts = opt_.maxAttempts;
  p.liveWindow = liveWindow();
  p.noWorkerTimeout = std::chrono::seconds(opt_.noWorkerTimeoutSec);
  p.leaseSeconds = opt_.leaseSeconds;
  p.expectWorkers = opt_.expectWorkers;
  return p;
}

void Master::onPoisoned(uint64_t id, const std::string& why, const std::string& count) {
  Brick& b = bricks_[id];
  if (std::exchange(b.held, false)) verifying_.erase(b.id);
  report_.poisoned.push_back(PoisonedBrick{b.id, b.lo, b.hi, why});
  spdlog::error("brick {} [{},{},{})-({},{},{}) poisoned after {}: {}", b.id, b.lo[0], b.lo[1], b.lo[2], b.hi[0],
                b.hi[1], b.hi[2], count, why);
}

// A task for brick `id` to `rid`; false if there is no route to it (LeaseTable::dispatch puts the
// brick back and gives the peer nothing more).
bool Master::sendTask(zmq::socket_t& router, const std::string& rid, uint64_t id, uint32_t attempt) {
  const Brick& b = bricks_[id];
  Envelope e;
  e.set_job_id(jobId_);
  Task* t = e.mutable_task();
  t->set_brick_id(b.id);
  t->set_attempt(attempt);
  for (int a = 0; a < 3; ++a) {
    t->add_lo(b.lo[a]);
    t->add_hi(b.hi[a]);
  }
  return send(router, rid, e);
}

}  // namespace frep::farm::detail
