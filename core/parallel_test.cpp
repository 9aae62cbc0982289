// parallelFor (core/parallel.h): every index once, the same results whatever the thread count,
// exceptions carried to the caller, and calls that meet the kept worker threads busy — nested in a
// body, or from two threads at once — run on threads of their own instead of waiting.
#include "core/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

namespace eik {
namespace {

std::thread::id caller;  // the test's own thread

// Marks each index of [0, n) in `seen`; every mark must be exactly one.
void expectEachIndexOnce(const std::vector<std::atomic<int>>& seen) {
  for (std::size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i].load(), 1) << "index " << i;
}

TEST(ParallelFor, VisitsEveryIndexOnceCallAfterCall) {
  // Many calls in a row (as a bake's steps make them), with grains that leave a short last chunk.
  for (int call = 0; call < 200; ++call) {
    const int n = 1 + call * 7 % 300;
    std::vector<std::atomic<int>> seen(static_cast<std::size_t>(n));
    parallelFor(0, n, [&](std::int64_t i) { seen[static_cast<std::size_t>(i)].fetch_add(1); }, 1 + call % 5);
    expectEachIndexOnce(seen);
  }
}

TEST(ParallelFor, NestedAndConcurrentCallsFinish) {
  // A body that calls parallelFor itself, and two threads calling at once: neither may wait for the
  // other's workers (the kept threads run one job at a time).
  constexpr int kOuter = 16, kInner = 64;
  std::vector<std::atomic<int>> seen(kOuter * kInner);
  auto nested = [&] {
    parallelFor(0, kOuter, [&](std::int64_t o) {
      parallelFor(0, kInner, [&](std::int64_t i) { seen[static_cast<std::size_t>(o * kInner + i)].fetch_add(1); });
    });
  };
  nested();
  expectEachIndexOnce(seen);
  for (auto& s : seen) s.store(0);
  std::vector<std::atomic<int>> other(5000);
  std::thread second([&] {
    for (int k = 0; k < 20; ++k)
      parallelFor(0, 250, [&](std::int64_t i) { other[static_cast<std::size_t>(k * 250 + i)].fetch_add(1); });
  });
  nested();
  second.join();
  expectEachIndexOnce(seen);
  expectEachIndexOnce(other);
}

TEST(ParallelFor, ThreadsStartedEarlyServeTheCallsAndAStartWhileBusyIsLeftOut) {
  // startWorkerThreads before any call (the viewer, before its driver loads), again, and from
  // within a body while the kept threads run it (nothing started, nothing waited for): every call
  // still visits every index once. A start that left the pool marked busy would send every later
  // call to threads of its own, which the thread ids below tell apart (the kept ones repeat).
  startWorkerThreads();
  startWorkerThreads();
  std::vector<std::atomic<int>> seen(4096);
  parallelFor(0, 4096, [&](std::int64_t i) {
    if (i % 512 == 0) startWorkerThreads();
    seen[static_cast<std::size_t>(i)].fetch_add(1);
  });
  expectEachIndexOnce(seen);
  if (workerThreads() < 2) GTEST_SKIP() << "one worker thread: nothing kept";
  auto helperIds = [] {
    std::mutex m;
    std::vector<std::thread::id> ids;
    // Until a helper has taken an index (on a loaded machine the caller may take them all first).
    for (int attempt = 0; attempt < 100 && ids.empty(); ++attempt)
      parallelFor(0, 64, [&](std::int64_t) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));  // each thread gets some indices
        std::lock_guard<std::mutex> lock(m);
        if (std::this_thread::get_id() != caller) ids.push_back(std::this_thread::get_id());
      });
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  };
  caller = std::this_thread::get_id();
  const std::vector<std::thread::id> first = helperIds();
  std::vector<std::thread> keep_alive;  // new threads started meanwhile would get fresh ids
  for (int k = 0; k < 3; ++k) keep_alive.emplace_back([] { std::this_thread::sleep_for(std::chrono::milliseconds(50)); });
  const std::vector<std::thread::id> second = helperIds();
  for (std::thread& t : keep_alive) t.join();
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first, second) << "the kept threads serve both calls";
}

TEST(ParallelFor, CarriesTheBodysExceptionToTheCallerAndStaysUsable) {
  EXPECT_THROW(parallelFor(0, 1000,
                           [](std::int64_t i) {
                             if (i == 517) throw std::runtime_error("index 517");
                           }),
               std::runtime_error);
  std::vector<std::int64_t> values(1000, 0);
  parallelFor(0, 1000, [&](std::int64_t i) { values[static_cast<std::size_t>(i)] = i * i; });
  for (std::int64_t i = 0; i < 1000; ++i) ASSERT_EQ(values[static_cast<std::size_t>(i)], i * i);
}

}  // namespace
}  // namespace eik
