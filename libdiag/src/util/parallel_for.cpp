#include "diag/util/parallel_for.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace diag {

int parallel_threads(std::size_t n, int threads) {
  const int wanted =
      threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return static_cast<int>(std::clamp<std::size_t>(n, 1, static_cast<std::size_t>(wanted)));
}

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& task) {
  if (n == 0) return;
  std::vector<std::exception_ptr> failed(n);
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> first_failure{n};  // lowest failing index seen so far (n: none)
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      if (i > first_failure.load(std::memory_order_relaxed)) continue;
      try {
        task(i);
      } catch (...) {
        failed[i] = std::current_exception();
        std::size_t seen = first_failure.load();
        while (i < seen && !first_failure.compare_exchange_weak(seen, i)) {
        }
      }
    }
  };
  const int workers = parallel_threads(n, threads);
  {
    std::vector<std::jthread> pool;
    pool.reserve(static_cast<std::size_t>(workers - 1));
    for (int t = 1; t < workers; ++t) pool.emplace_back(worker);
    worker();
  }  // joined here
  const std::size_t first = first_failure.load();
  if (first < n) std::rethrow_exception(failed[first]);
}

}  // namespace diag
