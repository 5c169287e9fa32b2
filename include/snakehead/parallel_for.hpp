// Loops over independent items on the core's worker pool (worker_pool.hpp), in two splits:
// - parallel_for: [0, n) in contiguous ranges, one per thread, for sample loops of even cost (Newton-Euler along a
//   path, the ZMP check, piecewise polynomials, limit ratios). Each sample is computed as in the serial loop, so the
//   loop gives, bit for bit, what the serial loop gives.
// - parallel_for_each: items dealt one at a time, in order, to a number of workers, for items of uneven cost (TRAC-IK
//   batches, the workspace sweep's tiles); each worker may keep its own state (a solver, buffers), so results that
//   depend on the item alone do not depend on the thread count or on which worker took which item.
// Both run their first worker on the calling thread (unless it watches), and work the pool could not start there too.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>

#include "snakehead/core_threads.hpp"

namespace snakehead {

// Runs range(p) for p in [0, parts): p = 0 on the calling thread, the others on the pool (or, when no thread took
// them, on the calling thread after). Every range runs; an exception of any range is rethrown, that of the earliest
// range first, after every range has ended.
void run_ranges(long parts, const std::function<void(long)>& range);

// Runs body(begin, end) over [0, n) split into at most core_threads() contiguous ranges of at least `grain` samples
// (fewer samples than 2 * grain: one range, on the calling thread); range p is [n p / P, n (p + 1) / P).
template <class Body>
void parallel_for(long n, long grain, Body&& body) {
  const long parts = std::max(1L, std::min<long>(core_threads(), n / std::max(1L, grain)));
  if (parts <= 1) {
    if (n > 0) body(0L, n);
    return;
  }
  run_ranges(parts, [&](long p) { body(n * p / parts, n * (p + 1) / parts); });
}

// A watcher of a parallel_for_each: called on the calling thread once before any item starts and then about every
// `period` while the items run (between its own items when the calling thread has to work them); it returns false
// to stop the loop (no item is started after), and may throw (the loop stops; its exception is rethrown unless a
// worker's came first).
struct LoopWatch {
  std::function<bool()> keep_going;
  std::chrono::milliseconds period{100};
};

// Runs body(worker, item) for every item in [0, n), dealt one at a time in increasing order to
// min(threads, n) workers (at least one), worker 0 on the calling thread unless `watch` is given (the calling thread
// then watches). A worker stops taking items once the loop is stopped or an item has thrown; the first exception
// (in time) is rethrown after every worker has ended. Returns false when the watch stopped the loop.
bool parallel_for_each(long n, int threads, const std::function<void(int, long)>& body, const LoopWatch* watch = nullptr);

}  // namespace snakehead
