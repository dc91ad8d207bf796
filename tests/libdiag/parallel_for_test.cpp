// parallel_for: every item once, the same results at every thread count, and the lowest failing
// item's exception whatever the thread count.
#include "diag/util/parallel_for.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

TEST(ParallelFor, RunsEveryItemExactlyOnce) {
  for (int threads : {1, 2, 3, 8, 0}) {
    std::vector<std::atomic<int>> calls(1000);
    diag::parallel_for(calls.size(), threads, [&](std::size_t i) { ++calls[i]; });
    for (std::size_t i = 0; i < calls.size(); ++i) ASSERT_EQ(calls[i].load(), 1) << i;
  }
}

TEST(ParallelFor, GivesTheSameBytesAtEveryThreadCount) {
  auto run = [](int threads) {
    std::vector<double> y(513);
    diag::parallel_for(y.size(), threads, [&](std::size_t i) {
      double s = 0;  // a per-item computation long enough for the threads to interleave
      for (int k = 1; k <= 2000; ++k) s += std::sin(0.001 * static_cast<double>(i * k)) / k;
      y[i] = s;
    });
    return y;
  };
  const std::vector<double> one = run(1);
  for (int threads : {2, 4, 7, 0}) EXPECT_EQ(run(threads), one) << threads << " threads";
}

TEST(ParallelFor, RethrowsTheLowestFailingItemWhateverTheThreadCount) {
  for (int repeat = 0; repeat < 20; ++repeat) {
    for (int threads : {1, 2, 4, 16}) {
      try {
        diag::parallel_for(200, threads, [](std::size_t i) {
          if (i % 37 == 5) throw std::runtime_error("item " + std::to_string(i));
        });
        FAIL() << "no exception";
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "item 5") << threads << " threads";
      }
    }
  }
}

TEST(ParallelFor, RunsEveryItemBelowTheFirstFailure) {
  std::vector<std::atomic<int>> calls(300);
  EXPECT_THROW(diag::parallel_for(calls.size(), 4,
                                  [&](std::size_t i) {
                                    ++calls[i];
                                    if (i == 250) throw std::logic_error("late");
                                  }),
               std::logic_error);
  for (std::size_t i = 0; i <= 250; ++i) ASSERT_EQ(calls[i].load(), 1) << i;
}

TEST(ParallelFor, DoesNothingForNoItemsAndCapsTheThreadsAtTheItems) {
  diag::parallel_for(0, 4, [](std::size_t) { FAIL(); });
  EXPECT_EQ(diag::parallel_threads(3, 8), 3);
  EXPECT_EQ(diag::parallel_threads(0, 8), 1);
  EXPECT_EQ(diag::parallel_threads(100, 5), 5);
  EXPECT_GE(diag::parallel_threads(100, 0), 1);
}

}  // namespace
