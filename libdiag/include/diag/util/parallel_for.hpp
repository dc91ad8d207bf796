// One way to run independent items on several threads.
//
// parallel_for(n, threads, task) calls task(i) for i = 0 .. n-1 on up to `threads` threads (the
// calling thread is one of them; threads <= 0: every hardware thread). Items are handed out in
// index order from a shared counter, so which thread runs an item varies from run to run; the
// results must not: each task(i) may depend on its index only and write only its own outputs.
// Then the bytes are the same at any thread count.
//
// Failures are deterministic too: when tasks throw, the exception of the lowest-numbered failing
// item is rethrown after every thread stopped, whatever the thread count. Items numbered above a
// failure already seen are skipped (they could not change which failure is reported); every item
// below it runs.
#pragma once

#include <cstddef>
#include <functional>

namespace diag {

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& task);

// The thread count parallel_for uses for `threads` and n items: threads <= 0 is every hardware
// thread (at least 1); never more than n (at least 1).
int parallel_threads(std::size_t n, int threads);

}  // namespace diag
