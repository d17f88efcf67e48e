#pragma once
// parallel_for over [0, n): chunks handed out by an atomic counter to `threads` workers; the
// calling thread reports progress. The body must write only its own outputs (then the result is
// independent of the thread count). The first exception (lowest chunk) is rethrown.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace impactdeck::study::detail {

/// The exception of the lowest failing chunk among those that failed (the caller holds its lock).
struct FirstError {
  std::exception_ptr error;
  std::size_t chunk = std::numeric_limits<std::size_t>::max();
  void keep(std::size_t c, std::exception_ptr e) {
    if (c < chunk) {
      chunk = c;
      error = std::move(e);
    }
  }
};

inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

/// The same over whole chunks: body(begin, end) for each chunk [begin, end) (a body that works on
/// groups of items, e.g. the sweep's grouped kernel).
template <class RangeBody>
unsigned parallel_for_ranges(std::size_t n, unsigned threads, std::size_t chunk, RangeBody&& body,
                             const std::function<void(std::size_t, std::size_t)>& progress) {
  threads = resolve_threads(threads);
  chunk = std::max<std::size_t>(1, chunk);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, chunks)));

  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex m;
  std::condition_variable cv;
  FirstError first_error;
  unsigned running = threads;

  auto work = [&] {
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) break;
      const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
      if (c >= chunks) break;
      const std::size_t begin = c * chunk, end = std::min(n, begin + chunk);
      try {
        body(begin, end);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        first_error.keep(c, std::current_exception());
        stop = true;
      }
      done.fetch_add(end - begin, std::memory_order_relaxed);
    }
    std::lock_guard<std::mutex> lock(m);
    --running;
    cv.notify_all();
  };

  if (threads == 1) {
    // Same chunking, in the calling thread, with progress between chunks.
    auto last = std::chrono::steady_clock::now();
    for (std::size_t c = 0; c < chunks && !stop; ++c) {
      const std::size_t begin = c * chunk, end = std::min(n, begin + chunk);
      body(begin, end);
      done += end - begin;
      const auto now = std::chrono::steady_clock::now();
      if (progress && now - last > std::chrono::milliseconds(100)) {
        progress(done.load(), n);
        last = now;
      }
    }
    if (progress) progress(done.load(), n);
    return 1;
  }

  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
  {
    std::unique_lock<std::mutex> lock(m);
    while (running > 0) {
      cv.wait_for(lock, std::chrono::milliseconds(100));
      if (progress && running > 0) {
        lock.unlock();
        progress(done.load(), n);
        lock.lock();
      }
    }
  }
  for (auto& t : pool) t.join();
  if (first_error.error) std::rethrow_exception(first_error.error);
  if (progress) progress(done.load(), n);
  return threads;
}

template <class Body>
unsigned parallel_for(std::size_t n, unsigned threads, std::size_t chunk, Body&& body,
                      const std::function<void(std::size_t, std::size_t)>& progress) {
  return parallel_for_ranges(
      n, threads, chunk,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) body(i);
      },
      progress);
}

}  // namespace impactdeck::study::detail
