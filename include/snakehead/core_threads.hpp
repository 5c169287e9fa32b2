// How many threads the core's batch work may use at once in this process: TRAC-IK's batches (TracIK::solve_many),
// a workspace sweep without an explicit thread count, and the sample loops of parallel_for.hpp (Newton-Euler along
// a path, the ZMP check of a motion).
//
// A process that is one of several workers on a machine (a process pool, a Dask worker) should use its share, so
// that the workers together use the cores once instead of each of them using all of them. The default follows the
// environment as BLAS and OpenMP libraries do: SNAKEHEAD_NUM_THREADS, else OMP_NUM_THREADS (Dask's workers set it
// to 1), else every hardware thread.
#pragma once

namespace snakehead {

// The environment variable that sets the default (a whole number in [1, limits::kMaxThreads]).
inline constexpr const char* kCoreThreadsVariable = "SNAKEHEAD_NUM_THREADS";

// The threads the core's batch work may use: the value set_core_threads set, else the default above (>= 1).
// InputError naming SNAKEHEAD_NUM_THREADS when that variable is set to anything but such a number.
int core_threads();

// The machine's hardware threads (std::thread::hardware_concurrency, at least 1).
int hardware_threads();

// Sets it for this process (1 <= n <= limits::kMaxThreads, else InputError); 0 restores the default.
// Takes effect from the next batch; safe from any thread.
void set_core_threads(int n);

}  // namespace snakehead
