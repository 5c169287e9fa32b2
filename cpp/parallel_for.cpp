#include "snakehead/parallel_for.hpp"

#include <atomic>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <vector>

#include "snakehead/worker_pool.hpp"

namespace snakehead {

void run_ranges(long parts, const std::function<void(long)>& range) {
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(parts));
  const auto run = [&](long p) {
    try {
      range(p);
    } catch (...) {
      errors[static_cast<std::size_t>(p)] = std::current_exception();
    }
  };
  WorkerPool& pool = WorkerPool::process();
  std::vector<WorkerPool::JobPtr> jobs;
  long handed = 1;  // ranges 1 .. handed - 1 have jobs
  try {
    jobs.reserve(static_cast<std::size_t>(parts - 1));
    for (long p = 1; p < parts; ++p, ++handed) {
      jobs.push_back(std::make_shared<WorkerPool::Job>([&run, p] { run(p); }));
      pool.submit(jobs.back());
    }
  } catch (...) {  // no memory for another job: the calling thread runs the rest
  }
  run(0);
  for (const auto& job : jobs) pool.run_or_wait(job);  // the ranges no thread took run here
  for (long p = handed; p < parts; ++p) run(p);
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

namespace {

// One parallel_for_each: the next item, the stop flag, the first error and the workers that have ended.
class ItemLoop {
 public:
  ItemLoop(long n, const std::function<void(int, long)>& body) : n_(n), body_(body) {}

  // Worker w: items until none is left or the loop is stopped. A worker on the watching thread (no pool thread took
  // it) also asks the watch between its items, every period, so that a stop is heard however the work was dealt.
  void work(int w, const LoopWatch* watch = nullptr) {
    auto asked = std::chrono::steady_clock::now();
    try {
      for (long i; !stop_.load(std::memory_order_relaxed) && (i = next_.fetch_add(1)) < n_;) {
        body_(w, i);
        if (watch != nullptr && std::chrono::steady_clock::now() - asked >= watch->period) {
          ask(*watch);
          asked = std::chrono::steady_clock::now();
        }
      }
    } catch (...) {
      fail(std::current_exception());
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++ended_;
    }
    cv_.notify_all();
  }

  // Stops the loop; e (if any) is rethrown at the end unless an earlier one was.
  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = e;
    stop_ = true;
  }

  // Asks the watch whether to go on: false stops the loop (and the loop reports it), an exception fails it.
  void ask(const LoopWatch& watch) {
    try {
      if (!watch.keep_going()) {
        watch_stopped_ = true;
        stop_ = true;
      }
    } catch (...) {
      fail(std::current_exception());
    }
  }

  bool stopped() const { return stop_.load(); }
  bool stopped_by_watch() const { return watch_stopped_.load(); }

  // Waits until `workers` have ended or `period` has passed; true when they have ended.
  bool wait_for(int workers, std::chrono::milliseconds period) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, period, [&] { return ended_ >= workers; });
  }

  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const long n_;
  const std::function<void(int, long)>& body_;
  std::atomic<long> next_{0};
  std::atomic<bool> stop_{false};
  std::atomic<bool> watch_stopped_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  int ended_ = 0;
  std::exception_ptr error_;
};

// The watcher's side: the watch every period until the `workers` started have ended.
void watch_loop(ItemLoop& loop, int workers, const LoopWatch& watch) {
  while (!loop.wait_for(workers, watch.period))
    if (!loop.stopped()) loop.ask(watch);
}

}  // namespace

bool parallel_for_each(long n, int threads, const std::function<void(int, long)>& body, const LoopWatch* watch) {
  const int workers = static_cast<int>(std::max<long>(1, std::min<long>(std::max(threads, 1), n)));
  ItemLoop loop(n, body);
  if (watch != nullptr) {  // a stop asked for before the loop (a pending Ctrl-C) is heard before any item starts
    loop.ask(*watch);
    if (loop.stopped()) {
      loop.rethrow();
      return false;
    }
  }
  WorkerPool& pool = WorkerPool::process();
  std::vector<char> here(static_cast<std::size_t>(workers), 1);  // workers the calling thread runs
  std::vector<WorkerPool::JobPtr> jobs;
  try {
    jobs.reserve(static_cast<std::size_t>(workers));
    for (int w = watch != nullptr ? 0 : 1; w < workers; ++w) {
      jobs.push_back(std::make_shared<WorkerPool::Job>([&loop, w] { loop.work(w); }));
      if (!pool.submit(jobs.back()) && pool.cancel(jobs.back()))
        jobs.pop_back();  // no thread could take it at once
      else
        here[static_cast<std::size_t>(w)] = 0;
    }
  } catch (...) {  // no memory for another job: the calling thread runs the rest
  }
  if (watch != nullptr && !jobs.empty()) watch_loop(loop, static_cast<int>(jobs.size()), *watch);
  for (int w = 0; w < workers; ++w)
    if (here[static_cast<std::size_t>(w)]) loop.work(w, watch);
  for (const auto& job : jobs) pool.run_or_wait(job);
  loop.rethrow();
  return !loop.stopped_by_watch();
}

}  // namespace snakehead
