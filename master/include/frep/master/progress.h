// Progress of a job: a bar on a terminal (the status line), or JSON events (one object per line)
// for batch systems. Throttled to a few updates per second.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace frep::farm {

// The bar's text: "[###.....] 3/8 bricks  1.25 M evals/s  ETA 12 s  workers 2". Until the first
// brick is done there is no estimate: "ETA --", not a false "ETA 0 s".
std::string progressLine(uint64_t done, uint64_t total, double evalsPerSec, double etaSeconds, int workers);

// The estimate from the elapsed time and the share done; < 0 (unknown) before any is done.
double etaSeconds(uint64_t done, uint64_t total, double elapsedSeconds);

// The bar's text during mesh simplification (SimplifyOptions::progress's stages 0 to 4):
// "[###.....] simplifying: pass 2 of 5, 120/400 blocks".
std::string simplifyLine(int stage, uint64_t done, uint64_t total);

// A SimplifyOptions::progress for the bar and/or JSON events ({"event":"progress","phase":
// "simplify","pass":P,"done":D,"total":T}), thread-safe, throttled like Progress; nothing if
// neither is wanted. The bar's line is ended by the last call (pass 3 complete).
std::function<void(int, uint64_t, uint64_t)> simplifyProgress(bool bar, bool json);

class Progress {
 public:
  Progress(bool bar, bool json, uint64_t total);
  void update(uint64_t done, uint64_t pointEvals, int workersAlive, bool force = false);
  void finish(uint64_t done, uint64_t pointEvals, int workersAlive);

 private:
  bool bar_, json_;
  uint64_t total_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace frep::farm
