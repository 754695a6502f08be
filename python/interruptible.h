// The Python module's long calls (sample, mesh, measure, eval) under the core's interrupter
// (frep/interrupt/interrupter.h): Ctrl-C raises KeyboardInterrupt within a fraction of a second
// and an optional progress callback sees the run advance.
//
// The core runs on a thread of its own without the GIL. The calling thread, Python's main one
// where signal handlers run, wakes every 50 ms, takes the GIL, calls PyErr_CheckSignals and
// hands the latest progress report to the callback; either may cancel the run, which then ends
// at its next check (Interrupted) and is joined before the Python exception is raised. The
// callback thus always runs on the caller's thread, with the GIL, never from the core's threads.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "frep/interrupt/interrupter.h"

namespace frep::python {

namespace py = pybind11;

// Raised when the progress callback returns False.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled by the progress callback") {}
};

class Interruptible {
 public:
  // progress: None, or a callable (stage: str, done: int, total: int); returning False cancels.
  explicit Interruptible(py::object progress) : progress_(std::move(progress)) {}

  // The interrupter to give the core's options (also installed on the run's thread).
  const Interrupter& interrupter() const { return run_; }

  // Runs fn() and returns its result; the caller holds the GIL.
  template <typename Fn>
  auto operator()(Fn&& fn) -> decltype(fn()) {
    using R = decltype(fn());
    std::optional<R> result;
    std::exception_ptr error;
    bool done = false;
    std::thread worker([&] {
      InterruptScope scope(&run_);
      try {
        result.emplace(fn());
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex_);
      done = true;
      wake_.notify_all();
    });
    bool pythonError = false, callbackCancelled = false;
    for (;;) {
      bool finished;
      {
        py::gil_scoped_release unlocked;
        std::unique_lock<std::mutex> lock(mutex_);
        finished = wake_.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
      }
      if (pythonError || callbackCancelled) {
        if (finished) break;
        continue;  // cancelled: wait for the run's next check
      }
      if (PyErr_CheckSignals() != 0) {
        pythonError = true;
      } else if (!relayProgress(pythonError)) {
        callbackCancelled = true;
      }
      if (pythonError || callbackCancelled) run_.cancel();
      if (finished) break;
    }
    {
      py::gil_scoped_release unlocked;
      worker.join();
    }
    if (pythonError) throw py::error_already_set();
    if (error) {
      try {
        std::rethrow_exception(error);
      } catch (const Interrupted&) {
        throw Cancelled();
      }
    }
    return std::move(*result);
  }

 private:
  // Hands the latest report (if new) to the callback. False: it returned False. An exception
  // from it sets pythonError (the Python error stays set, raised once the run is joined).
  bool relayProgress(bool& pythonError) {
    if (progress_.is_none()) return true;
    ProgressReport report{"", 0, 0};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!fresh_) return true;
      fresh_ = false;
      report = latest_;
    }
    try {
      py::object r = progress_(std::string(report.stage), report.done, report.total);
      return !(r.is(py::bool_(false)));
    } catch (py::error_already_set& e) {
      e.restore();
      pythonError = true;
      return true;
    }
  }

  py::object progress_;
  std::mutex mutex_;
  std::condition_variable wake_;
  ProgressReport latest_{"", 0, 0};
  bool fresh_ = false;
  Interrupter run_{nullptr, [this](const ProgressReport& p) {
                     std::lock_guard<std::mutex> lock(mutex_);
                     latest_ = p;
                     fresh_ = true;
                     return true;
                   }};
};

// fn() (no Python in it) under a fresh run: the core's long call of a module function.
template <typename Fn>
auto interruptible(py::object progress, Fn&& fn) -> decltype(fn()) {
  Interruptible run(std::move(progress));
  return run(std::forward<Fn>(fn));
}

}  // namespace frep::python
