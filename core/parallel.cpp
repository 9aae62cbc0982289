#include "core/parallel.h"

#include <atomic>
#include <cstdlib>
#include <string>

namespace eik {

unsigned workerThreads() {
  if (const char* env = std::getenv("EIKONAL_THREADS")) {
    int n = std::atoi(env);
    if (n > 0) return static_cast<unsigned>(n);
  }
  unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1u : n;
}

void parallelFor(std::int64_t begin, std::int64_t end, const std::function<void(std::int64_t)>& body,
                 std::int64_t grain) {
  if (end <= begin) return;
  grain = std::max<std::int64_t>(grain, 1);
  const std::int64_t chunks = (end - begin + grain - 1) / grain;
  const unsigned threads = static_cast<unsigned>(std::min<std::int64_t>(workerThreads(), chunks));
  if (threads <= 1) {
    for (std::int64_t i = begin; i < end; ++i) body(i);
    return;
  }
  std::atomic<std::int64_t> next{begin};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    try {
      for (;;) {
        std::int64_t start = next.fetch_add(grain);
        if (start >= end) break;
        std::int64_t stop = std::min(end, start + grain);
        for (std::int64_t i = start; i < stop; ++i) body(i);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next.store(end);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace eik
