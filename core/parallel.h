// Minimal deterministic data parallelism over an index range (std::thread; the worker threads are
// kept between calls, core/parallel.cpp). Work is split into contiguous chunks, so results written
// per index are the same whatever the thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace eik {

// Number of worker threads (EIKONAL_THREADS overrides hardware_concurrency()).
unsigned workerThreads();

// Calls body(i) for every i in [begin, end), from up to workerThreads() threads. Indices are
// handed out in chunks of `grain` (dynamic scheduling); exceptions are re-thrown on the caller.
void parallelFor(std::int64_t begin, std::int64_t end, const std::function<void(std::int64_t)>& body,
                 std::int64_t grain = 1);

}  // namespace eik
