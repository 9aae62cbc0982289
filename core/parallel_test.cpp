// parallelFor (core/parallel.h): every index once, the same results whatever the thread count,
// exceptions carried to the caller, and calls that meet the kept worker threads busy — nested in a
// body, or from two threads at once — run on threads of their own instead of waiting.
#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

namespace eik {
namespace {

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
