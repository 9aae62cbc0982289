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

// Starts parallelFor's kept threads now rather than at its first call. A program that loads a large
// library on another thread (the viewer's OpenGL driver: gl::DriverPreload) calls this before it
// starts that load: a thread started while the dynamic loader is relocating the library waits for
// it to finish (glibc sets up a new thread's TLS under the loader's lock), which stalled the
// viewer's scene reading for the 45 ms the driver takes to load (BENCHMARKS.md, issue 13,
// twenty-eighth part).
void startWorkerThreads();

}  // namespace eik
