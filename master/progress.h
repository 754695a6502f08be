// Progress of a job: a bar on a terminal, or JSON events (one object per line) for batch
// systems. Throttled to a few updates per second.
#pragma once

#include <chrono>
#include <cstdint>

namespace frep::farm {

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
