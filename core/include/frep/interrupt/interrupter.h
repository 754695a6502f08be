// One cancel-and-progress contract for the core's long algorithms: sample, meshGrid,
// simplifyMesh, castRays, measureMassProperties and the extremum searches under them. The shape
// is OpenVDB's (util/NullInterrupter.h: every long tool takes an interrupter) and libfive's
// (render/brep/settings.hpp: a progress callback and an atomic cancel flag).
//
// A caller makes one Interrupter per run and passes it in the algorithm's options
// (`interrupt`). The run polls it at every parallel chunk, at every extremum search and every 64
// box splits inside one, so a cancel ends it within milliseconds of work per thread; the
// algorithm then throws Interrupted and returns nothing (measureMassProperties alone returns its
// last complete round, marked stopped). Nested work sees the run's interrupter through the
// calling thread (InterruptScope): the evaluators, which reach the extremum searches, take no
// parameter, and parallelChunks carries the scope onto the threads that run its chunks.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>

namespace frep {

// Thrown by a run whose interrupter was cancelled. Callers that stop on it write nothing.
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

struct ProgressReport {
  const char* stage;  // "sample", "mesh", "simplify", "render", "measure"
  uint64_t done = 0, total = 0;
};

class Interrupter {
 public:
  // Returns false to cancel the run. Calls are serialised (never two at once), from any thread.
  using Progress = std::function<bool(const ProgressReport&)>;

  Interrupter() = default;
  // flag: an outside cancel, e.g. set by a signal handler (read, never written).
  explicit Interrupter(const std::atomic<bool>* flag, Progress progress = {})
      : flag_(flag), progress_(std::move(progress)) {}
  Interrupter(const Interrupter&) = delete;
  Interrupter& operator=(const Interrupter&) = delete;

  void cancel() const noexcept { own_.store(true, std::memory_order_relaxed); }
  bool cancelled() const noexcept {
    return own_.load(std::memory_order_relaxed) || (flag_ && flag_->load(std::memory_order_relaxed));
  }
  void check() const {
    if (cancelled()) throw Interrupted();
  }
  // Tells the progress callback (if any), then check()s.
  void progress(const char* stage, uint64_t done, uint64_t total) const;

 private:
  mutable std::atomic<bool> own_{false};  // cancel() is const: a run holds its interrupter const
  const std::atomic<bool>* flag_ = nullptr;
  Progress progress_;
  mutable std::mutex mutex_;
};

// The interrupter of the run the calling thread works for; null outside any.
const Interrupter* currentInterrupter() noexcept;

// Throws Interrupted when the calling thread's run is cancelled (one thread-local and one
// relaxed atomic load: cheap enough for every search).
inline void checkInterrupt() {
  if (const Interrupter* i = currentInterrupter()) i->check();
}

// Reports progress to the current run's interrupter (if any), then checks it.
inline void reportProgress(const char* stage, uint64_t done, uint64_t total) {
  if (const Interrupter* i = currentInterrupter()) i->progress(stage, done, total);
}

// Makes `run` the calling thread's interrupter until the scope ends (the outer one is restored).
class InterruptScope {
 public:
  explicit InterruptScope(const Interrupter* run) noexcept;
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

  // An algorithm's entry: the options' interrupter if given, else the caller's (a nested run).
  static const Interrupter* choose(const Interrupter* given) noexcept { return given ? given : currentInterrupter(); }

 private:
  const Interrupter* outer_;
};

}  // namespace frep
