#include "snakehead/core_threads.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <string>
#include <thread>

#include "snakehead/limits.hpp"
#include "snakehead/model.hpp"

namespace snakehead {
namespace {

std::atomic<int> chosen{0};  // set_core_threads's value; 0: the default

// A whole number in [1, kMaxThreads] as the whole text, else 0.
int parse_count(const char* text) {
  if (text == nullptr || *text == '\0') return 0;
  errno = 0;
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  if (errno != 0 || *end != '\0' || n < 1 || n > limits::kMaxThreads) return 0;
  return static_cast<int>(n);
}

// The process's default, read once: SNAKEHEAD_NUM_THREADS, else OMP_NUM_THREADS (which Dask's workers and many
// job schedulers set to a worker's share), else every hardware thread.
int default_threads() {
  static const int n = [] {
    if (const char* ours = std::getenv(kCoreThreadsVariable)) {
      const int v = parse_count(ours);
      if (v == 0)
        throw InputError(std::string(kCoreThreadsVariable) + " must be a whole number within [1, " +
                         std::to_string(limits::kMaxThreads) + "], got '" + ours + "'");
      return v;
    }
    const int omp = parse_count(std::getenv("OMP_NUM_THREADS"));
    return omp > 0 ? omp : hardware_threads();
  }();
  return n;
}

}  // namespace

int hardware_threads() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

int core_threads() {
  const int n = chosen.load(std::memory_order_relaxed);
  return n > 0 ? n : default_threads();
}

void set_core_threads(int n) {
  if (n < 0 || n > limits::kMaxThreads)
    throw InputError("threads must be within [1, " + std::to_string(limits::kMaxThreads) + "] (0: the default), got " +
                     std::to_string(n));
  chosen.store(n, std::memory_order_relaxed);
}

}  // namespace snakehead
