#include "diag/dsp/fir.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>
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
  diag::LowpassDesign bad;
  bad.cutoff_fraction = 0.5;
  EXPECT_THROW(diag::design_lowpass(bad), diag::InputError);
}

// The designs the simulator and the resampler were built with, written out as they were: the
// Blackman low-pass of the simulator's decimator and the Kaiser half-band of the resampler's
// decimation stages. design_lowpass must give the same bits (the simulated and analysed outputs
// must not move), so the comparison is exact.
std::vector<double> blackman_as_before(double fc, int half_length) {
  const int n = 2 * half_length + 1;
  std::vector<double> h(n);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = i - half_length;
    const double sinc = x == 0.0 ? 2 * fc : std::sin(2 * kPi * fc * x) / (kPi * x);
    const double a = 2 * kPi * i / (n - 1);
    const double w = 0.42 - 0.5 * std::cos(a) + 0.08 * std::cos(2 * a);
    h[i] = sinc * w;
    sum += h[i];
  }
  for (double& v : h) v /= sum;
  return h;
}

TEST(LowpassDesign, BlackmanGivesTheSimulatorsDecimatorTapsBitForBit) {
  for (const auto& [fc, half] :
       {std::pair{0.45 / 2, 28}, std::pair{0.09, 50}, std::pair{0.0225, 250}, std::pair{0.3, 1},
        std::pair{0.01, 1000}}) {
    diag::LowpassDesign d;
    d.cutoff_fraction = fc;
    d.half_length = half;
    EXPECT_EQ(diag::design_lowpass(d), blackman_as_before(fc, half)) << fc << ", M = " << half;
  }
}

TEST(LowpassDesign, KaiserHalfBandGivesTheResamplersTapsBitForBit) {
  constexpr int kReach = 55;  // the resampler's half-band: taps at odd n up to 55, beta for 100 dB
  const double beta = 0.1102 * (100.0 - 8.7);
  diag::LowpassDesign d;
  d.cutoff_fraction = 0.25;
  d.half_length = kReach;
  d.window = diag::FirWindow::kKaiser;
  d.kaiser_beta = beta;
  d.unit_dc_gain = false;
  const std::vector<double> h = diag::design_lowpass(d);
  EXPECT_EQ(h[kReach], 0.5);
  const double i0_beta = std::cyl_bessel_i(0.0, beta);
  for (int n = 1; n <= kReach; n += 2) {
    const double r = static_cast<double>(n) / kReach;
    const double x = kPi * n / 2;
    const double before =
        0.5 * (std::sin(x) / x) * std::cyl_bessel_i(0.0, beta * std::sqrt(1 - r * r)) / i0_beta;
    EXPECT_EQ(h[kReach + n], before) << n;
    EXPECT_EQ(h[kReach - n], before) << n;
  }
}

TEST(LowpassDesign, GivenWindowIsUsedSymmetricallyAndScaledToUnitDcGain) {
  diag::LowpassDesign d;
  d.cutoff_fraction = 0.1;
  d.half_length = 3;
  d.window = diag::FirWindow::kGiven;
  d.window_values = {0.1, 0.5, 0.9, 1.0, 0.9, 0.5, 0.2};  // the last value is not used
  const std::vector<double> h = diag::design_lowpass(d);
  double sum = 0;
  for (double v : h) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-15);  // one rounding per tap
  for (std::size_t j = 0; j < h.size(); ++j) EXPECT_EQ(h[j], h[h.size() - 1 - j]);
  d.window_values.pop_back();
  EXPECT_THROW(diag::design_lowpass(d), diag::InputError);
  d.window = diag::FirWindow::kKaiser;
  d.kaiser_beta = -1;
  EXPECT_THROW(diag::design_lowpass(d), diag::InputError);
}

}  // namespace
