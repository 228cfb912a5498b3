#pragma once
// parallel_items(n, threads, f): f(i, t) for every item i in [0, n) on `threads` threads
// (t in [0, threads): the thread's index, for per-thread state; thread 0 is the caller), the
// items handed out in increasing order from one atomic counter. An exception of f is kept per
// item; once every thread has joined, the first in item order is rethrown. Callers write each
// item's result to its own slot, so the output does not depend on the number of threads.
// Used by the scene simulator (streams), the streaming decode (bursts' metrics) and the demo
// (codes x distances).
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace ranging {

template <class F>
void parallel_items(std::size_t n, std::size_t threads, F f) {
  std::vector<std::exception_ptr> errors(n);
  std::atomic<std::size_t> next{0};
  auto work = [&](std::size_t t) {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        f(i, t);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& t : pool) t.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace ranging
