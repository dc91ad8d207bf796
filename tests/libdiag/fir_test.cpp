#include "diag/dsp/fir.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "diag/error.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

std::vector<double> decimate(int factor, const std::vector<double>& x, std::size_t block) {
  diag::Decimator d(factor);
  std::vector<double> out;
  for (std::size_t i = 0; i < x.size(); i += block) {
    const std::size_t n = std::min(block, x.size() - i);
    d.push(std::span<const double>(x.data() + i, n), out);
  }
  d.finish(out);
  return out;
}

// A tone in the passband comes through with its amplitude and phase: output k is the input at
// index k D. Tolerance 2e-3: the Blackman design's passband ripple is below 1e-3 (74 dB
// stopband), doubled for the tone's own interpolation between output samples.
TEST(Decimator, PassesAToneInThePassbandAlignedWithTheInput) {
  const int D = 5;
  const double fs_in = 100000.0, f = 0.3 * fs_in / D / 2;  // 30 % of the output Nyquist
  std::vector<double> x(20000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(2 * kPi * f * i / fs_in + 0.3);
  const std::vector<double> y = decimate(D, x, 977);
  ASSERT_EQ(y.size(), (x.size() + D - 1) / D);
  for (std::size_t k = 200; k + 200 < y.size(); ++k) {
    EXPECT_NEAR(y[k], x[k * D], 2e-3) << k;
  }
}

// A tone just above the output Nyquist frequency (which would alias into the band) is removed:
// below 1e-3 (-60 dB; the design's stopband is about -74 dB).
TEST(Decimator, RemovesAToneAboveTheOutputNyquistFrequency) {
  const int D = 4;
  const double fs_in = 80000.0, f = 1.05 * fs_in / D / 2;
  std::vector<double> x(40000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(2 * kPi * f * i / fs_in);
  const std::vector<double> y = decimate(D, x, 4096);
  double peak = 0.0;
  for (std::size_t k = 200; k + 200 < y.size(); ++k) peak = std::max(peak, std::abs(y[k]));
  EXPECT_LT(peak, 1e-3);
}

// A linear ramp (a shaft angle at constant speed) is reproduced exactly in the interior: the
// taps are symmetric with unit DC gain. Round-off bound 1e-9 on values up to 2e4.
TEST(Decimator, KeepsALinearRampExactly) {
  std::vector<double> x(10000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 2.0 * i + 1.0;
  const std::vector<double> y = decimate(8, x, 100);
  for (std::size_t k = 100; k + 100 < y.size(); ++k) EXPECT_NEAR(y[k], x[k * 8], 1e-9);
}

TEST(Decimator, RefusesBadParameters) {
  EXPECT_THROW(diag::Decimator(0), diag::InputError);
  EXPECT_THROW(diag::Decimator(4, 1.0), diag::InputError);
  EXPECT_THROW(diag::lowpass_taps(0.5, 10), diag::InputError);
}

}  // namespace
