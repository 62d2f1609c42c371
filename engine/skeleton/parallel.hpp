#pragma once
// A minimal parallel loop for the skeleton's per-vertex queries (visibility, inside tests):
// independent iterations split into contiguous chunks over the hardware threads.

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace sdfkit::skeleton::detail {

// Calls body(begin, end) on disjoint ranges covering [0, n), concurrently on up to
// std::thread::hardware_concurrency() threads (one, on the calling thread, when n is below
// `serial_below`). `body` must only write per-index state; results are then independent of the
// thread count.
template <class Body>
void parallel_for(std::size_t n, Body&& body, std::size_t serial_below = 1024) {
  const std::size_t threads =
      std::min<std::size_t>(std::max(1u, std::thread::hardware_concurrency()), (n + serial_below - 1) / std::max<std::size_t>(serial_below, 1));
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

}  // namespace sdfkit::skeleton::detail
