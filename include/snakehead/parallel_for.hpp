// Sample loops split over the core's threads (core_threads.hpp): each thread takes one contiguous range of the
// samples, so a loop whose samples are independent gives, bit for bit, what the serial loop gives.
#pragma once

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

#include "snakehead/core_threads.hpp"

namespace snakehead {

// Runs body(begin, end) over [0, n) split into at most core_threads() contiguous ranges of at least `grain` samples
// (fewer samples than 2 * grain: one range, on the calling thread). The first range runs on the calling thread, and
// so do the ranges whose thread could not be started.
// An exception of any range is rethrown, that of the earliest range first, after every range has ended.
template <class Body>
void parallel_for(long n, long grain, Body&& body) {
  const long parts = std::max(1L, std::min<long>(core_threads(), n / std::max(1L, grain)));
  if (parts <= 1) {
    if (n > 0) body(0L, n);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(parts));
  const auto range = [&](long p) {
    try {
      body(n * p / parts, n * (p + 1) / parts);
    } catch (...) {
      errors[static_cast<std::size_t>(p)] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  long started = 1;  // ranges 1 .. started-1 have their threads
  try {
    threads.reserve(static_cast<std::size_t>(parts - 1));
    for (long p = 1; p < parts; ++p, ++started) threads.emplace_back(range, p);
  } catch (...) {  // no thread to be had (a process at its limit): the calling thread runs the rest
  }
  range(0);
  for (long p = started; p < parts; ++p) range(p);
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace snakehead
