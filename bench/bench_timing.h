// Timing shared by the benchmarks.
#pragma once

#include <ctime>

namespace frep::bench {

// CPU seconds of this process: on a shared machine a single-threaded run's CPU time is the
// stable measure (wall time varies with the load).
inline double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace frep::bench
