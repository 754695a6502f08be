// The in-process run (--workers 0): the master computes every brick itself, with the workers'
// code (frep_brick), then commits them as a worker's results. The only file of the master that
// computes bricks (master/CMakeLists.txt, docs/architecture.md).

#include "frep/farm/crc32.h"
#include "frep/interrupt/interrupter.h"
#include "frep/worker/brick.h"
#include "master.h"

namespace frep::farm::detail {

void Master::runInProcess() {
  TapePtr tape = compileJobModel(job_);
  describeErrorBounds(*tape, &report_.errorBounds);
  for (const std::string& line : describeExactTerms(job_)) report_.errorBounds.push_back(line);
  // A stop signal ends the brick being computed too: its searches and parallel chunks check the
  // core's interrupter (frep/interrupt/interrupter.h), so a brick of many seconds stops at once.
  const Interrupter stop(&gStop);
  InterruptScope scope(&stop);
  for (Brick& b : bricks_) {
    if (lease(b.id).phase == BrickPhase::Done) continue;
    if (gStop) {
      report_.interrupted = true;
      return;
    }
    rethrowMergeError();
    auto t0 = Clock::now();
    BrickOutput out;
    try {
      out = computeBrick(tape, job_, b.lo, b.hi, opt_.threads);
    } catch (const Interrupted&) {
      report_.interrupted = true;  // the bricks before it are in the journal
      return;
    }
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
    progress_->update(leases_.done(), report_.pointEvals, 1);
  }
}

}  // namespace frep::farm::detail
