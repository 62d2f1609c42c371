#pragma once
// A minimal parallel loop for independent per-item work (k-ring smoothing, the skeleton's
// per-vertex queries): contiguous chunks over plain threads, the first on the calling thread.

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace sdfkit {

// The machine's hardware threads, asked once: glibc answers std::thread::hardware_concurrency()
// by reading /sys on every call, which cost about 4 % of a skeleton of a mesh of a few hundred
// vertices, whose loops are mostly too short to split anyway.
inline unsigned hardware_threads() {
  static const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  return threads;
}

// Calls body(begin, end) on disjoint ranges covering [0, n), concurrently on up to
// `max_threads` threads (0 = hardware_threads()) with about `min_per_thread`
// items or more each (one range, on the calling thread, when n is below it). `body` must only
// write per-index state; results are then independent of the thread count.
template <class Body>
void parallel_for(std::size_t n, Body&& body, std::size_t min_per_thread = 1024, unsigned max_threads = 0) {
  const std::size_t wanted = (n + min_per_thread - 1) / std::max<std::size_t>(min_per_thread, 1);
  const std::size_t threads =
      wanted <= 1 ? wanted : std::min<std::size_t>(max_threads > 0 ? max_threads : hardware_threads(), wanted);
  if (threads <= 1) {
    body(std::size_t{0}, n);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (n + threads - 1) / threads;
  for (std::size_t t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { body(std::min(n, t * chunk), std::min(n, (t + 1) * chunk)); });
  body(std::size_t{0}, std::min(n, chunk));
  for (std::thread& th : pool) th.join();
}

}  // namespace sdfkit
