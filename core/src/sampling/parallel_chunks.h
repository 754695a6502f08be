// Internal to core: one way to run a loop over [0, n) in chunks, and to sort, with a
// thread-count option (1: serial on the calling thread, > 1: that many threads, 0: TBB's
// default), shared by the sampler, both meshers and the simplifier. Each chunk runs under the
// caller's interrupter (frep/interrupt/interrupter.h), checked before it starts.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>

#include "frep/interrupt/interrupter.h"

namespace frep {

// fn(begin, end) for chunks of at least `grain` items.
template <typename Fn>
void parallelChunks(size_t n, size_t grain, int threads, Fn&& fn) {
  const Interrupter* run = currentInterrupter();
  auto body = [&](const tbb::blocked_range<size_t>& r) {
    InterruptScope scope(run);  // a TBB thread may come from another run: this chunk is ours
    if (run) run->check();
    fn(r.begin(), r.end());
  };
  if (n == 0) return;
  if (threads == 1) {
    body(tbb::blocked_range<size_t>(0, n));
  } else if (threads > 1) {
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), body); });
  } else {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), body);
  }
}

// std::sort(first, last, less) with the same thread-count option. For a strict total order
// (no two elements equal) the result does not depend on the threads.
template <typename It, typename Less>
void parallelSort(It first, It last, Less less, int threads) {
  if (threads == 1) {
    std::sort(first, last, less);
  } else if (threads > 1) {
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_sort(first, last, less); });
  } else {
    tbb::parallel_sort(first, last, less);
  }
}

}  // namespace frep
