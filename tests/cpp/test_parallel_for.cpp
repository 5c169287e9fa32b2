// The core's loops on its worker pool (parallel_for.hpp, worker_pool.hpp): every item once, the same split, the
// exceptions and the watch.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "snakehead/core_threads.hpp"
#include "snakehead/parallel_for.hpp"
#include "snakehead/worker_pool.hpp"

namespace {

TEST(ParallelFor, EverySampleOnceAndTheEarliestErrorRethrown) {
  snakehead::set_core_threads(4);
  std::vector<int> seen(1000, 0);
  snakehead::parallel_for(1000, 10, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) ++seen[static_cast<std::size_t>(k)];
  });
  EXPECT_EQ(std::vector<int>(1000, 1), seen);
  try {
    snakehead::parallel_for(1000, 10, [](long begin, long) {
      if (begin > 0) throw std::runtime_error("range at " + std::to_string(begin));
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "range at 250");  // the second of four ranges, the earliest that failed
  }
  int calls = 0;
  snakehead::parallel_for(15, 10, [&](long begin, long end) { calls += static_cast<int>(end - begin) + 100 * (begin != 0); });
  EXPECT_EQ(calls, 15);  // fewer than two ranges' worth: one range, on the calling thread
  snakehead::set_core_threads(0);
}

TEST(ParallelFor, RangesRunBesideTheCallingThread) {
  // A range waits until every other range has started: that ends only when the ranges run at once.
  snakehead::set_core_threads(4);
  std::atomic<int> started{0};
  std::atomic<bool> alone{false};
  snakehead::parallel_for(4, 1, [&](long, long) {
    ++started;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started.load() < 4)
      if (std::chrono::steady_clock::now() > deadline) {
        alone = true;
        break;
      } else {
        std::this_thread::yield();
      }
  });
  EXPECT_FALSE(alone.load());
  snakehead::set_core_threads(0);
}

TEST(ParallelForEach, EveryItemOnceEachWorkerItsOwn) {
  for (int threads : {1, 3, 8}) {
    std::vector<int> seen(500, 0), by(500, -1);
    const bool finished = snakehead::parallel_for_each(500, threads, [&](int w, long i) {
      ++seen[static_cast<std::size_t>(i)];
      by[static_cast<std::size_t>(i)] = w;
    });
    EXPECT_TRUE(finished);
    EXPECT_EQ(std::vector<int>(500, 1), seen);
    for (int w : by) EXPECT_TRUE(w >= 0 && w < threads) << w;
  }
  int calls = 0;
  EXPECT_TRUE(snakehead::parallel_for_each(0, 4, [&](int, long) { ++calls; }));
  EXPECT_EQ(calls, 0);
}

TEST(ParallelForEach, TheFirstErrorStopsTheLoopAndIsRethrown) {
  std::atomic<long> after{0};
  try {
    snakehead::parallel_for_each(100000, 4, [&](int, long i) {
      if (i == 10) throw std::runtime_error("item 10");
      if (i > 10) ++after;
      std::this_thread::sleep_for(std::chrono::microseconds(10));
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "item 10");
  }
  EXPECT_LT(after.load(), 20000);  // the workers stopped taking items
}

TEST(ParallelForEach, TheWatchRunsOnTheCallingThreadAndMayStopTheLoop) {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<long> done{0};
  int watched = 0;
  bool on_caller = true;
  const snakehead::LoopWatch stop_soon{[&] {
                                         on_caller = on_caller && std::this_thread::get_id() == caller;
                                         return ++watched < 3;
                                       },
                                       std::chrono::milliseconds(5)};
  const bool finished = snakehead::parallel_for_each(100000, 2, [&](int, long) {
    EXPECT_NE(std::this_thread::get_id(), caller);  // the calling thread only watches
    ++done;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }, &stop_soon);
  EXPECT_FALSE(finished);
  EXPECT_TRUE(on_caller);
  EXPECT_EQ(watched, 3);
  EXPECT_LT(done.load(), 100000);
  const snakehead::LoopWatch throws{[] () -> bool { throw std::runtime_error("from the watch"); },
                                    std::chrono::milliseconds(1)};
  try {
    snakehead::parallel_for_each(100000, 2, [](int, long) { std::this_thread::sleep_for(std::chrono::microseconds(50)); },
                                 &throws);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "from the watch");
  }
}

TEST(ParallelForEach, AStopBeforeTheStartRunsNoItemAndOneWorkerStillHearsTheWatch) {
  std::atomic<long> done{0};
  const snakehead::LoopWatch no{[] { return false; }, std::chrono::milliseconds(1000)};
  EXPECT_FALSE(snakehead::parallel_for_each(1000, 2, [&](int, long) { ++done; }, &no));
  EXPECT_EQ(done.load(), 0);  // asked before the first item, however short the loop
  // One worker (on the pool, or on the calling thread between its asks when no pool thread is free): still heard.
  int watched = 0;
  const snakehead::LoopWatch third{[&] { return ++watched < 3; }, std::chrono::milliseconds(2)};
  const bool finished = snakehead::parallel_for_each(100000, 1, [&](int, long) {
    ++done;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }, &third);
  EXPECT_FALSE(finished);
  EXPECT_EQ(watched, 3);
  EXPECT_LT(done.load(), 100000);
}

TEST(WorkerPool, AJobTakenBackRunsOnTheCallerAndAnAbandonedOneEndsOnItsOwn) {
  snakehead::WorkerPool& pool = snakehead::WorkerPool::process();
  std::atomic<bool> ran{false};
  auto job = std::make_shared<snakehead::WorkerPool::Job>([&] { ran = true; });
  pool.submit(job);
  pool.run_or_wait(job);  // ran on a worker (waited for), or taken back and run here
  EXPECT_TRUE(ran.load());
  // A job that outlives its submitter's interest: it owns what it touches and ends when told to.
  auto stop = std::make_shared<std::atomic<bool>>(false);
  auto abandoned = std::make_shared<snakehead::WorkerPool::Job>([stop] {
    while (!stop->load()) std::this_thread::yield();
  });
  EXPECT_TRUE(pool.submit(abandoned));
  stop->store(true);
  pool.cancel(abandoned);
  EXPECT_GE(pool.size(), 1);
}

}  // namespace
