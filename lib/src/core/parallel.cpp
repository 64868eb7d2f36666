#include "celc/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

namespace celc {

namespace {

/// Starts up to `count` threads running `body`. A thread that cannot be
/// started is not an error: the threads already running (and the caller)
/// do its share of the work.
template <typename Body>
std::vector<std::thread> startThreads(std::size_t count, const Body& body) {
  std::vector<std::thread> pool;
  pool.reserve(count);
  try {
    for (std::size_t i = 0; i < count; ++i) pool.emplace_back(body);
  } catch (...) {
  }
  return pool;
}

void joinAll(std::vector<std::thread>& pool) {
  for (auto& t : pool) t.join();
}

}  // namespace

int resolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void parallelFor(std::size_t n_jobs, int n_threads, const std::function<void(std::size_t)>& fn) {
  if (n_jobs == 0) return;
  const std::size_t threads = std::min(static_cast<std::size_t>(resolveThreadCount(n_threads)), n_jobs);
  if (threads == 1) {
    for (std::size_t i = 0; i < n_jobs; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&] {
    while (!failed.load(std::memory_order_relaxed)) {
      const std::size_t i = next.fetch_add(1);
      if (i >= n_jobs) return;
      try {
        fn(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool = startThreads(threads - 1, worker);
  worker();  // the calling thread is one of the workers
  joinAll(pool);
  if (error) std::rethrow_exception(error);
}

namespace detail {

void orderedPipeline(int n_threads, std::size_t max_in_flight, std::size_t max_weight,
                     const std::function<std::size_t(std::size_t)>& weight,
                     const std::function<bool(std::size_t)>& produce,
                     const std::function<void(std::size_t)>& work,
                     const std::function<void(std::size_t)>& consume) {
  const std::size_t cap = std::max<std::size_t>(1, max_in_flight);
  auto runInline = [&] {
    while (produce(0)) {
      work(0);
      consume(0);
    }
  };
  const int threads = resolveThreadCount(n_threads);
  if (threads == 1) return runInline();

  std::mutex mu;
  std::condition_variable work_ready, work_done;
  std::deque<std::size_t> queue;       // sequence numbers waiting for a worker
  std::vector<char> finished(cap, 0);  // per slot: worked on, waiting to be consumed
  std::vector<std::size_t> weights(cap, 0);  // per slot: the job's weight (max_weight > 0)
  std::size_t held_weight = 0;         // of the jobs produced and not yet worked on to the end
  std::size_t last_weight = 0;         // of the last job produced: the estimate of the next one
  bool closed = false;                 // nothing more will be queued
  std::exception_ptr error;
  auto recordError = [&] {
    std::lock_guard<std::mutex> lock(mu);
    if (!error) error = std::current_exception();
  };
  // With a weight bound, the next job is produced while the jobs held
  // leave room for one as heavy as the last, and always when none is held.
  // Called with `mu` held.
  auto mayProduce = [&] { return max_weight == 0 || held_weight == 0 || held_weight + last_weight <= max_weight; };

  auto worker = [&] {
    for (;;) {
      std::size_t seq = 0;
      bool skip = false;
      {
        std::unique_lock<std::mutex> lock(mu);
        work_ready.wait(lock, [&] { return !queue.empty() || closed; });
        if (queue.empty()) return;
        seq = queue.front();
        queue.pop_front();
        skip = error != nullptr;  // the run is failing: no more work
      }
      if (!skip) {
        try {
          work(seq % cap);
        } catch (...) {
          recordError();
        }
      }
      {
        std::lock_guard<std::mutex> lock(mu);
        finished[seq % cap] = 1;
        held_weight -= weights[seq % cap];  // work() has released the job
      }
      work_done.notify_all();
    }
  };
  std::vector<std::thread> pool = startThreads(static_cast<std::size_t>(threads), worker);
  if (pool.empty()) return runInline();

  std::size_t produced = 0, consumed = 0;
  bool more = true;
  // Consumes finished jobs in sequence order. Waits for the next one when the
  // pipeline is full (by count or by weight) or nothing more will be
  // produced. False on error.
  auto consumeReady = [&]() -> bool {
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mu);
        if (error) return false;
        if (consumed == produced) return true;
        const std::size_t slot = consumed % cap;
        if (!finished[slot]) {
          auto mayGoOn = [&] { return more && produced - consumed < cap && mayProduce(); };
          if (mayGoOn()) return true;
          work_done.wait(lock, [&] { return finished[slot] || error || mayGoOn(); });
          if (error) return false;
          if (!finished[slot]) return true;
        }
        finished[slot] = 0;
      }
      consume(consumed % cap);
      ++consumed;
    }
  };
  try {
    while (consumeReady() && more) {
      if (!produce(produced % cap)) {
        more = false;  // the next consumeReady drains the rest
        continue;
      }
      const std::size_t w = max_weight > 0 ? weight(produced % cap) : 0;
      {
        std::lock_guard<std::mutex> lock(mu);
        weights[produced % cap] = w;
        held_weight += w;
        last_weight = w;
        queue.push_back(produced);
        ++produced;
      }
      work_ready.notify_one();
    }
  } catch (...) {
    recordError();
  }
  {
    std::lock_guard<std::mutex> lock(mu);
    closed = true;
    if (error) queue.clear();  // jobs not started yet are dropped
  }
  work_ready.notify_all();
  joinAll(pool);
  if (error) std::rethrow_exception(error);
}

}  // namespace detail

}  // namespace celc
