#include "snakehead/worker_pool.hpp"

#include <algorithm>
#include <deque>
#include <thread>
#include <vector>

#include <unistd.h>  // getpid: fork safety

namespace snakehead {

// The threads of one process and their queue.
struct WorkerPool::Crew {
  Crew() : owner(::getpid()) {}

  bool submit(const JobPtr& job) {
    std::lock_guard<std::mutex> lock(mutex);
    try {
      queue.push_back(job);
    } catch (...) {  // no memory for the queue: the job stays its submitter's (cancel takes it back)
      return false;
    }
    bool taken = idle >= static_cast<int>(queue.size());
    if (!taken && static_cast<int>(threads.size()) < kMaxWorkers) {
      try {
        threads.emplace_back([this] { loop(); });  // it waits for the mutex, then takes a queued job
        taken = true;
      } catch (...) {  // no thread to be had (a process at its limit): the job waits
      }
    }
    cv.notify_one();
    return taken;
  }

  bool cancel(const JobPtr& job) {
    std::lock_guard<std::mutex> lock(mutex);
    if (job->running) return false;
    auto it = std::find(queue.begin(), queue.end(), job);
    if (it != queue.end()) queue.erase(it);
    return true;
  }

  int size() {
    std::lock_guard<std::mutex> lock(mutex);
    return static_cast<int>(threads.size());
  }

  void loop() {
    for (;;) {
      JobPtr job;
      {
        std::unique_lock<std::mutex> lock(mutex);
        ++idle;
        cv.wait(lock, [&] { return !queue.empty(); });
        --idle;
        job = std::move(queue.front());
        queue.pop_front();
        job->running = true;
      }
      job->fn();
      {
        std::lock_guard<std::mutex> lock(job->m);
        job->done = true;
      }
      job->cv.notify_all();
    }
  }

  const pid_t owner;  // the process whose threads these are
  std::vector<std::thread> threads;  // never joined: the crew lives as long as its process
  std::mutex mutex;
  std::condition_variable cv;
  std::deque<JobPtr> queue;
  int idle = 0;  // threads waiting for a job
};

WorkerPool& WorkerPool::process() {
  static WorkerPool* pool = new WorkerPool;  // never destroyed (see the header)
  return *pool;
}

// This process's crew: made by its first user, in a forked child by the child's first user (a compare-exchange, so
// that threads of the child that come at once agree on one crew).
WorkerPool::Crew& WorkerPool::crew() {
  Crew* crew = crew_.load(std::memory_order_acquire);
  const pid_t me = ::getpid();  // one system call: nothing beside a thread hand-off
  if (crew != nullptr && crew->owner == me) return *crew;
  auto mine = std::make_unique<Crew>();
  if (crew_.compare_exchange_strong(crew, mine.get(), std::memory_order_acq_rel)) return *mine.release();
  return *crew;  // another thread of this process made it first (ours, without threads, is freed)
}

bool WorkerPool::submit(const JobPtr& job) { return crew().submit(job); }

bool WorkerPool::cancel(const JobPtr& job) { return crew().cancel(job); }

void WorkerPool::run_or_wait(const JobPtr& job) {
  if (cancel(job)) {
    job->fn();
    return;
  }
  std::unique_lock<std::mutex> lock(job->m);
  job->cv.wait(lock, [&] { return job->done; });
}

void WorkerPool::cancel_or_wait(const JobPtr& job) {
  if (cancel(job)) return;
  std::unique_lock<std::mutex> lock(job->m);
  job->cv.wait(lock, [&] { return job->done; });
}

int WorkerPool::size() { return crew().size(); }

}  // namespace snakehead
