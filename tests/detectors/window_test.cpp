#include "detect/spectral/window.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "diag/error.hpp"

namespace {

using detect::WindowSymmetry;
using detect::WindowType;

constexpr double kRoundOff = 1e-14;  // a handful of cos() evaluations and sums of O(1) terms

// Hand-computed: the periodic Hann window of 4 samples is 0.5 - 0.5 cos(2 pi j / 4).
TEST(Window, PeriodicHannOfFourIsZeroHalfOneHalf) {
  const auto w = detect::make_window(WindowType::kHann, 4);
  const std::vector<double> expected{0.0, 0.5, 1.0, 0.5};
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(w[j], expected[j], kRoundOff) << j;
}

// Symmetric Hamming of 5: 0.54 - 0.46 cos(2 pi j / 4) = {0.08, 0.54, 1, 0.54, 0.08}.
TEST(Window, SymmetricHammingOfFiveMatchesHandValues) {
  const auto w = detect::make_window(WindowType::kHamming, 5, WindowSymmetry::kSymmetric);
  const std::vector<double> expected{0.08, 0.54, 1.0, 0.54, 0.08};
  for (std::size_t j = 0; j < 5; ++j) EXPECT_NEAR(w[j], expected[j], kRoundOff) << j;
}

// A periodic window of n is the symmetric one of n + 1 without its last sample, and a symmetric
// window is symmetric.
TEST(Window, PeriodicIsSymmetricOfOneMoreWithoutTheLastSample) {
  for (WindowType t : {WindowType::kHann, WindowType::kHamming, WindowType::kBlackmanHarris,
                       WindowType::kFlatTop, WindowType::kFlatTopMatlab}) {
    const auto p = detect::make_window(t, 64, WindowSymmetry::kPeriodic);
    const auto s = detect::make_window(t, 65, WindowSymmetry::kSymmetric);
    for (std::size_t j = 0; j < 64; ++j) EXPECT_NEAR(p[j], s[j], kRoundOff) << to_string(t);
    for (std::size_t j = 0; j < 65; ++j) EXPECT_NEAR(s[j], s[64 - j], kRoundOff) << to_string(t);
  }
}

// For a periodic cosine-sum window with n > 2 (terms - 1), the DFT orthogonality of the cosines
// gives exactly sum w = n a0 and sum w^2 = n (a0^2 + sum_{k>0} a_k^2 / 2), so
// CG = a0 and ENBW = 1 + sum a_k^2 / (2 a0^2). The published values (Harris 1978 Table I:
// Hann 1.50, Hamming 1.36, 4-term Blackman-Harris 2.00 bins; Heinzel 2002 HFT95 3.8112 bins,
// MATLAB flattopwin 3.77) are checked at their printed precision.
TEST(Window, CoherentGainAndEnbwMatchTheClosedFormAndPublishedValues) {
  struct Case {
    WindowType type;
    std::vector<double> a;
    double published_enbw;
    double printed_precision;
  };
  const double hft = 1.0 + 1.9383379 + 1.3045202 + 0.4028270 + 0.0350665;
  const std::vector<Case> cases{
      {WindowType::kRectangular, {1.0}, 1.0, 1e-12},
      {WindowType::kHann, {0.5, 0.5}, 1.50, 0.005},
      {WindowType::kHamming, {0.54, 0.46}, 1.36, 0.005},
      {WindowType::kBlackmanHarris, {0.35875, 0.48829, 0.14128, 0.01168}, 2.00, 0.005},
      {WindowType::kFlatTop,
       {1.0 / hft, 1.9383379 / hft, 1.3045202 / hft, 0.4028270 / hft, 0.0350665 / hft},
       3.8112,
       0.00005},
      {WindowType::kFlatTopMatlab,
       {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368},
       3.77,
       0.005},
  };
  for (const Case& c : cases) {
    const auto w = detect::make_window(c.type, 1000);
    double sum_sq = 0.0;
    for (std::size_t k = 1; k < c.a.size(); ++k) sum_sq += c.a[k] * c.a[k];
    const double enbw = 1.0 + sum_sq / (2.0 * c.a[0] * c.a[0]);
    EXPECT_NEAR(detect::coherent_gain(w), c.a[0], kRoundOff) << to_string(c.type);
    EXPECT_NEAR(detect::enbw_bins(w), enbw, 1e-12) << to_string(c.type);
    EXPECT_NEAR(detect::enbw_bins(w), c.published_enbw, c.printed_precision) << to_string(c.type);
  }
}

// Every window here peaks at 1 (the flat-tops up to the 1e-9 rounding of their coefficients).
TEST(Window, PeaksAtOneInTheMiddle) {
  for (WindowType t : {WindowType::kHann, WindowType::kHamming, WindowType::kBlackmanHarris,
                       WindowType::kFlatTop, WindowType::kFlatTopMatlab}) {
    const auto w = detect::make_window(t, 101, WindowSymmetry::kSymmetric);
    EXPECT_NEAR(w[50], 1.0, 2e-8) << to_string(t);
  }
}

TEST(Window, OneSampleIsOneAndZeroSamplesIsAnError) {
  EXPECT_EQ(detect::make_window(WindowType::kHann, 1), std::vector<double>{1.0});
  EXPECT_THROW(detect::make_window(WindowType::kHann, 0), diag::InputError);
}

TEST(Window, NamesRoundTripAndUnknownNamesAreRejected) {
  for (WindowType t :
       {WindowType::kRectangular, WindowType::kHann, WindowType::kHamming,
        WindowType::kBlackmanHarris, WindowType::kFlatTop, WindowType::kFlatTopMatlab}) {
    EXPECT_EQ(detect::parse_window(to_string(t)), t);
  }
  try {
    detect::parse_window("kaiser", "welch.window");
    FAIL() << "no exception";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("welch.window"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("kaiser"), std::string::npos) << e.what();
  }
}

// shared_window_sums: the values of make_window and their sums in index order, bit for bit (the
// amplitude spectrum's scaling and ENBW read them instead of summing again), for every type and
// after the cache has moved on to other lengths and back.
TEST(Window, SharedWindowSumsAreMakeWindowsExactly) {
  for (int round = 0; round < 2; ++round) {
    for (std::size_t n : {7u, 256u, 4096u, 200000u, 300u, 12u, 5000u, 64u}) {
      for (WindowType t : {WindowType::kHann, WindowType::kFlatTop, WindowType::kRectangular}) {
        const std::vector<double> w = detect::make_window(t, n);
        double s = 0, s2 = 0;
        for (double v : w) {
          s += v;
          s2 += v * v;
        }
        const detect::SharedWindow sw = detect::shared_window_sums(t, n);
        ASSERT_EQ(*sw.values, w);
        EXPECT_EQ(sw.sum, s);
        EXPECT_EQ(sw.sum_sq, s2);
        EXPECT_EQ(*detect::shared_window(t, n), w);
      }
    }
  }
}

}  // namespace
