#include "frep/interrupt/interrupter.h"

namespace frep {
namespace {
thread_local const Interrupter* tCurrent = nullptr;
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
