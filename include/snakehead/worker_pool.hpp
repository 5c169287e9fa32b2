// The core's one pool of threads, shared by everything in the process that runs work beside the calling thread:
// parallel_for.hpp's loops (Newton-Euler along a path, the ZMP check, TRAC-IK batches, the workspace sweep's tiles)
// and a raced TRAC-IK call's SQP half. Threads are made on first need and kept (a thread takes ~20-50 us to start,
// as long as a short IK call): a job is handed to an idle thread, or to a new one when none is idle, up to
// kMaxWorkers threads; beyond, jobs wait in the queue for a thread to free (or for their submitter to take them
// back).
//
// A job is shared between its submitter and the thread that runs it, so that the submitter may wait for it (a loop's
// range, which writes into the caller's arrays), take it back while no thread has started it (and run it itself),
// or abandon it (a raced call's SQP half, which owns everything it touches and is told to stop).
//
// Fork. The threads and their queue (a crew) belong to the process that made them: a forked child has none of the
// threads, and the crew's mutex may be held there forever (a worker held it at the fork). So the pool remembers its
// crew's process: a forked child neither uses nor joins the parent's crew (that copy is left as it is, a small leak
// per fork) and makes a crew of its own when it is first used there.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>

namespace snakehead {

class WorkerPool {
 public:
  // At most this many threads (limits::kMaxThreads, and a raced IK call's SQP half beside each).
  static constexpr int kMaxWorkers = 512;

  struct Job {
    explicit Job(std::function<void()> f) : fn(std::move(f)) {}
    std::function<void()> fn;  // must not throw (jobs catch their own exceptions)
    bool running = false;      // guarded by the crew's mutex
    std::mutex m;
    std::condition_variable cv;
    bool done = false;  // guarded by m
  };
  using JobPtr = std::shared_ptr<Job>;

  // This process's pool (made on first use, never destroyed: its threads wait for work until the process ends).
  static WorkerPool& process();

  // Queues the job. True when a thread will take it at once (an idle one, or one made for it); false when none could
  // be had (kMaxWorkers busy, or the system refused a thread: it then waits for a thread to free) or the job could not
  // be queued (no memory: cancel takes it back).
  bool submit(const JobPtr& job);

  // Takes the job back (out of the queue, if it is there) unless a thread has taken it: true when none has (the job
  // will not run unless its submitter runs it). False when it is already running (or done).
  bool cancel(const JobPtr& job);

  // Takes the job back and runs it on the calling thread if no thread has started it, else waits until it has ended.
  void run_or_wait(const JobPtr& job);

  // Removes the job if it is still queued, else waits until it has ended.
  void cancel_or_wait(const JobPtr& job);

  // The pool's threads now (busy or idle).
  int size();

  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

 private:
  struct Crew;
  WorkerPool() = default;
  Crew& crew();
  std::atomic<Crew*> crew_{nullptr};  // this process's, or a parent's (a forked child's before its first use)
};

}  // namespace snakehead
