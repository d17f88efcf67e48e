#pragma once
// parallel_for over [0, n): chunks handed out by an atomic counter to `threads` workers; the
// calling thread reports progress. The body must write only its own outputs (then the result is
// independent of the thread count). The first exception (lowest range) is rethrown.
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

/// The exception of the lowest failing range (by its first item) among those that failed (the
/// caller holds its lock).
struct FirstError {
  std::exception_ptr error;
  std::size_t first = std::numeric_limits<std::size_t>::max();
  void keep(std::size_t begin, std::exception_ptr e) {
    if (begin < first) {
      first = begin;
      error = std::move(e);
    }
  }
};

inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

/// The same over whole ranges: body(begin, end) for each range [begin, end) (a body that works on
/// groups of items, e.g. the sweep's grouped kernel). Guided: a worker claims max(chunk,
/// min(max_chunk, remaining / (4 threads))) items, so that a long run costs few claims (two atomic
/// operations each, on lines the workers share) and gives a body that prefetches ahead long ranges,
/// while the last claims shrink to `chunk` and balance the threads. The ranges depend only on n,
/// threads, chunk and max_chunk (each claim's size follows from the position it starts at), not on
/// timing. max_chunk <= chunk: ranges of `chunk` items.
template <class RangeBody>
unsigned parallel_for_ranges(std::size_t n, unsigned threads, std::size_t chunk, std::size_t max_chunk,
                             RangeBody&& body, const std::function<void(std::size_t, std::size_t)>& progress) {
  threads = resolve_threads(threads);
  chunk = std::max<std::size_t>(1, chunk);
  max_chunk = std::max(chunk, max_chunk);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, chunks)));
  const std::size_t divisor = 4 * static_cast<std::size_t>(threads);
  auto claim_size = [&](std::size_t begin) {
    const std::size_t remaining = n - begin;
    return std::min(remaining, std::max(chunk, std::min(max_chunk, remaining / divisor)));
  };

  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex m;
  std::condition_variable cv;
  FirstError first_error;
  unsigned running = threads;

  auto work = [&] {
    std::size_t begin = next.load(std::memory_order_relaxed);
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) break;
      if (begin >= n) break;
      const std::size_t end = begin + claim_size(begin);
      if (!next.compare_exchange_weak(begin, end, std::memory_order_relaxed)) continue;  // begin reloaded
      try {
        body(begin, end);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        first_error.keep(begin, std::current_exception());
        stop = true;
      }
      done.fetch_add(end - begin, std::memory_order_relaxed);
      begin = next.load(std::memory_order_relaxed);
    }
    std::lock_guard<std::mutex> lock(m);
    --running;
    cv.notify_all();
  };

  if (threads == 1) {
    // The same ranges, in the calling thread, with progress between them.
    auto last = std::chrono::steady_clock::now();
    for (std::size_t begin = 0; begin < n && !stop;) {
      const std::size_t end = begin + claim_size(begin);
      body(begin, end);
      done += end - begin;
      begin = end;
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
      n, threads, chunk, chunk,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) body(i);
      },
      progress);
}

}  // namespace impactdeck::study::detail
