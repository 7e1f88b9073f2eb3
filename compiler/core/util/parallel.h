// Running independent jobs on a few threads, with results kept by index so
// that the outcome never depends on scheduling.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <thread>
#include <vector>

namespace substratec {

/// The worker count for `requested` (0: the machine's hardware threads), at
/// most `count` and at least 1.
inline std::size_t workerCount(std::size_t count, std::size_t requested) {
  std::size_t n = requested ? requested : std::max(1u, std::thread::hardware_concurrency());
  return std::max<std::size_t>(1, std::min(n, count));
}

/// Runs `work(i)` for every i in [0, count) on `workerCount(count, jobs)`
/// threads, the calling one included; `work` must only touch the state of
/// its own index (or synchronize). Returns when every job is done.
inline void parallelFor(std::size_t count, std::size_t jobs, const std::function<void(std::size_t)>& work) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < count;) work(i);
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < workerCount(count, jobs); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

}  // namespace substratec
