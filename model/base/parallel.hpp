#pragma once
// parallel_items(n, threads, f): f(i, t) for every item i in [0, n) on `threads` workers
// (t in [0, threads): the worker's index, for per-thread state; worker 0 is the caller), the
// items handed out in increasing order from one atomic counter. An exception of f is kept per
// item; once every worker has finished, the first in item order is rethrown. Callers write each
// item's result to its own slot, so the output does not depend on the number of threads.
// Used by the scene simulator (streams), the streaming decode (bursts' metrics) and the demo
// (codes x distances).
// The workers other than the caller run as oneTBB tasks in an arena of `threads` slots: TBB's
// threads persist between calls (a decode calls this once per block, about every 3 ms; a new
// std::thread per call cost a clone, an 8 MB stack and its page faults each time). Each worker
// takes its index t once, so per-thread state is never shared, also when a worker waits in a
// nested call.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

namespace ranging {

namespace detail {
// One arena per worker count, made on first use and kept (arenas are meant to live long). It
// has at most as many slots as the machine has threads (TBB's default concurrency: more slots
// than TBB has threads only made it print a warning); workers beyond that run as tasks on the
// threads there are, each still with its own index t.
inline tbb::task_arena& parallel_arena(std::size_t threads) {
  static std::mutex m;
  static std::map<std::size_t, std::unique_ptr<tbb::task_arena>> arenas;
  const std::lock_guard<std::mutex> lock(m);
  auto& a = arenas[threads];
  if (!a) {
    const auto slots = std::min<std::size_t>(threads, static_cast<std::size_t>(std::max(1, tbb::info::default_concurrency())));
    a = std::make_unique<tbb::task_arena>(static_cast<int>(slots));
  }
  return *a;
}
}  // namespace detail

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
  if (threads <= 1 || n <= 1) {
    work(0);
  } else {
    detail::parallel_arena(threads).execute([&] {
      tbb::task_group g;
      for (std::size_t t = 1; t < threads; ++t) g.run([&work, t] { work(t); });
      work(0);
      g.wait();
    });
  }
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace ranging
