#include "frep/interrupt/interrupter.h"

#ifdef __SANITIZE_THREAD__
#include <tbb/global_control.h>
#endif

namespace frep {
namespace {
thread_local const Interrupter* tCurrent = nullptr;

#ifdef __SANITIZE_THREAD__
// ThreadSanitizer builds only (tests/sanitize/run_sanitizers.sh): Debian's libtbb is not
// instrumented, so TSan cannot see TBB hand a task to another thread and reports every loop's
// range and captures as races. TBB's loops run on the thread that calls them instead; TSan then
// checks our own threads (the master, its merge thread, the worker's I/O and compute threads)
// with every access their loops make. Races between the chunks of one loop need an instrumented
// TBB; ASan runs those loops on all threads. This file is in every binary that runs a loop.
const tbb::global_control kTsanSerialTbb(tbb::global_control::max_allowed_parallelism, 1);
#endif
}  // namespace

void Interrupter::progress(const char* stage, uint64_t done, uint64_t total) const {
  if (progress_) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!progress_(ProgressReport{stage, done, total})) cancel();
  }
  check();
}

const Interrupter* currentInterrupter() noexcept { return tCurrent; }

InterruptScope::InterruptScope(const Interrupter* run) noexcept : outer_(tCurrent) { tCurrent = run; }

InterruptScope::~InterruptScope() { tCurrent = outer_; }

}  // namespace frep
