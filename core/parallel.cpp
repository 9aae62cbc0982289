#include "core/parallel.h"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace eik {
namespace {

unsigned hardwareThreads() {
  // std::thread::hardware_concurrency reads /sys/devices/system/cpu/online each time: once is enough.
  static const unsigned n = [] {
    const unsigned h = std::thread::hardware_concurrency();
    return h == 0 ? 1u : h;
  }();
  return n;
}

// Threads kept for parallelFor between calls: a bake calls it a few times a step, hundreds of times
// a run, and starting and joining two threads each time costs about 0.07 ms on a 2-core virtual
// machine (93 thread starts in the 64³ bake command). One job at a time: a parallelFor that finds
// the pool busy (another thread's, or one nested in a job's body) starts threads of its own, as
// every call did before the pool.
class WorkerPool {
 public:
  static WorkerPool& instance() {
    static WorkerPool pool;
    return pool;
  }

  // Runs `job` on `helpers` pool threads and on the calling thread, and returns once all have
  // finished it; false (nothing run) when the pool is busy.
  bool run(unsigned helpers, const std::function<void()>& job) {
    bool idle = false;
    if (!busy_.compare_exchange_strong(idle, true)) return false;  // a flag, not a mutex: a nested call
                                                                  // from this thread must see it set
    struct Release {
      std::atomic<bool>& flag;
      ~Release() { flag.store(false); }
    } release{busy_};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      while (threads_.size() < helpers) threads_.emplace_back([this] { serve(); });
      job_ = &job;
      ++generation_;
      wanted_ = helpers;
      running_ = helpers;
    }
    wake_.notify_all();
    job();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return running_ == 0; });
    job_ = nullptr;
    return true;
  }

  // Starts `helpers` threads (those missing), unless the pool is busy.
  void start(unsigned helpers) {
    bool idle = false;
    if (!busy_.compare_exchange_strong(idle, true)) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      while (threads_.size() < helpers) threads_.emplace_back([this] { serve(); });
    }
    busy_.store(false);
  }

  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

 private:
  WorkerPool() = default;

  void serve() {
    std::uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || (wanted_ > 0 && generation_ != seen); });
      if (stop_) return;
      seen = generation_;
      --wanted_;
      const std::function<void()>* job = job_;
      lock.unlock();
      (*job)();  // parallelFor's worker catches what the body throws
      lock.lock();
      if (--running_ == 0) done_.notify_all();
    }
  }

  std::atomic<bool> busy_{false};  // set while a job runs
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> threads_;
  const std::function<void()>* job_ = nullptr;
  std::uint64_t generation_ = 0;
  unsigned wanted_ = 0;   // pool threads still to take the job
  unsigned running_ = 0;  // pool threads that have not finished it
  bool stop_ = false;
};

}  // namespace

unsigned workerThreads() {
  if (const char* env = std::getenv("EIKONAL_THREADS")) {
    int n = std::atoi(env);
    if (n > 0) return static_cast<unsigned>(n);
  }
  return hardwareThreads();
}

void startWorkerThreads() {
  const unsigned threads = workerThreads();
  if (threads > 1) WorkerPool::instance().start(threads - 1);
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
  const std::function<void()> worker = [&] {
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
  if (!WorkerPool::instance().run(threads - 1, worker)) {
    std::vector<std::thread> pool;
    pool.reserve(threads - 1);
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace eik
