// Decimation before the angular resampling (resample.hpp, "Decimation first"): the half-band
// filter's response, a decimated plan against the direct one (tones, a chirp, out-of-band
// content), and the SSE2 and AVX2 paths giving the same bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "detect/angular/order_spectrum.hpp"
#include "detect/angular/resample.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

// Restores the automatic SIMD choice when a test that forces one ends.
struct AutoSimd {
  ~AutoSimd() { detect::set_resample_simd(detect::SimdPath::kAuto); }
};

bool same_bytes(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// The stated response (resample.hpp): passband [0, 0.22 fs] ripple 9.8e-6, stopband [0.28 fs,
// fs / 2] below -100 dB, zero delay (y[k] = H(f) x(2k) for a cosine away from the ends). The
// tolerances are the stated figures rounded up to 1e-5 (both were computed on a 20 000-point
// grid; the tones here fall between its points).
TEST(HalfBand, PassbandRippleAndStopbandAreAsStated) {
  constexpr double kRipple = 1.0e-5, kStop = 1.0e-5;
  const std::size_t n = 4000;
  for (int i = 0; i <= 60; ++i) {
    const double f = 0.5 * i / 60.0;  // cycles per input sample
    if (f > 0.22 && f < 0.28) continue;
    std::vector<double> x(n);
    for (std::size_t k = 0; k < n; ++k) x[k] = std::cos(2 * kPi * f * static_cast<double>(k));
    const std::vector<double> y = detect::decimate_half_band(x, 1);
    ASSERT_EQ(y.size(), (n + 1) / 2);
    double worst = 0;
    for (std::size_t k = 100; k + 100 < y.size(); ++k) {
      const double want = f <= 0.22 ? std::cos(2 * kPi * f * static_cast<double>(2 * k)) : 0.0;
      worst = std::max(worst, std::abs(y[k] - want));
    }
    EXPECT_LT(worst, f <= 0.22 ? kRipple : kStop) << "f = " << f;
  }
}

struct Fixture {
  double fs = 20e3;
  std::vector<double> pulses;
  std::vector<double> x;
  // Shaft angle [rev]: 10 rev/s speeding up by 4 % over 6 s.
  static double revs(double t) { return 0.31 + 10 * t + 0.5 * 0.07 * t * t; }
  explicit Fixture(double out_of_band_amplitude) {
    const double duration = 6.0;
    for (long k = 1;; ++k) {
      // revs(t) = k: the pulse times.
      const double c = 0.31 - static_cast<double>(k), a = 0.035, b = 10.0;
      const double t = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
      if (t > duration) break;
      pulses.push_back(t);
    }
    x.resize(static_cast<std::size_t>(duration * fs));
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double t = static_cast<double>(i) / fs, th = revs(t);
      // Orders 7.3, 31 and 55.5, and a chirp 150 -> 750 Hz: all in the passband of a plan of
      // 256 samples/rev (0.72 x 128 = 92 orders, 920 Hz).
      double v = std::cos(2 * kPi * 7.3 * th) + 0.5 * std::sin(2 * kPi * 31 * th + 0.3) +
                 0.25 * std::cos(2 * kPi * 55.5 * th) +
                 0.7 * std::cos(2 * kPi * (150 * t + 0.5 * 100 * t * t));
      // Above the angular Nyquist (1.28 - 1.33 kHz) and up to fs / 2: stopped by the
      // kernel with or without the decimation.
      v += out_of_band_amplitude * (std::cos(2 * kPi * 2500 * t) + std::cos(2 * kPi * 4700 * t) +
                                    std::cos(2 * kPi * 7300 * t) + std::cos(2 * kPi * 9600 * t));
      x[i] = v;
    }
  }
};

// The decimated plan against the direct one. In-band content only: they agree to the stated
// 1e-5 of the content per stage (passband ripple and stopband residue; two stages here) plus
// the two discrete kernels' different stopband leakage of the in-band content's images (at 10
// or 5 kHz from it: the far stopband of the kernel). Measured: 8.9e-6 for the in-band sum of
// amplitudes 2.45; tolerance 2 x 1e-5 of it. With out-of-band tones of amplitude 1 the kernels'
// -80 dB stopband (each <= 1e-4 of them) adds at most 2e-4 per tone: tolerance 2e-5 x 2.45 +
// 2e-4 x 4 (measured 1.0e-5).
TEST(DecimatedPlan, EqualsTheDirectPlanToTheStatedBound) {
  for (const double out_of_band : {0.0, 1.0}) {
    const Fixture fx(out_of_band);
    detect::ResampleOptions direct_opt;
    direct_opt.samples_per_rev = 256;
    detect::ResampleOptions opt = direct_opt;
    opt.decimation = 3;
    const auto direct = detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), direct_opt);
    const auto plan = detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), opt);
    // Angular Nyquist 1.33 kHz at most: within the passband edge of two stages (2.2 kHz), not
    // of three (1.1 kHz).
    EXPECT_EQ(plan.decimation(), 2);
    EXPECT_EQ(plan.n_samples(), (fx.x.size() + 3) / 4);
    EXPECT_DOUBLE_EQ(plan.fs_hz(), fx.fs / 4);
    ASSERT_EQ(plan.first_rev(), direct.first_rev());
    ASSERT_EQ(plan.revolutions(), direct.revolutions());
    const auto a = detect::resample_by_angle(fx.x, direct);
    const auto b = detect::resample_by_angle(detect::decimate_half_band(fx.x, 2), plan);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    double worst = 0;
    for (std::size_t m = 0; m < a.samples.size(); ++m)
      worst = std::max(worst, std::abs(a.samples[m] - b.samples[m]));
    const double in_band = 1 + 0.5 + 0.25 + 0.7;
    const double tol = 2e-5 * in_band + 2e-4 * 4 * out_of_band;
    EXPECT_LT(worst, tol) << "out-of-band amplitude " << out_of_band;
    std::cout << "out-of-band " << out_of_band << ": max |decimated - direct| = " << worst << "\n";
    // The one-call form decimates as its plan says: the same bytes.
    EXPECT_TRUE(
        same_bytes(detect::resample_by_angle(fx.x, fx.fs, fx.pulses, opt).samples, b.samples));
  }
}

// A plan whose angular Nyquist lies above the first stage's passband edge (0.22 fs) reads the
// record as it is; the length check names the decimation.
TEST(DecimatedPlan, TakesNoStageAboveThePassbandAndNamesTheLengthItNeeds) {
  const Fixture fx(0.0);
  detect::ResampleOptions opt;
  opt.samples_per_rev = 1024;  // Nyquist 5.1 kHz > 4.4 kHz
  opt.decimation = 2;
  EXPECT_EQ(detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), opt).decimation(), 0);
  opt.samples_per_rev = 256;
  const auto plan = detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), opt);
  ASSERT_GT(plan.decimation(), 0);
  try {
    (void)detect::resample_by_angle(fx.x, plan);
    ADD_FAILURE() << "no error for an undecimated record";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("decimate_half_band"), std::string::npos) << e.what();
  }
  opt.decimation = 5;
  EXPECT_THROW((void)detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), opt), std::exception);
  EXPECT_THROW((void)detect::decimate_half_band(fx.x, -1), std::exception);
}

// SSE2 and AVX2 give the same bytes: the decimator, the per-tap table path (a cutoff that
// follows the speed), the polyphase path (one cutoff) and two channels at once.
TEST(ResampleSimd, Sse2AndAvx2GiveTheSameBytes) {
  const AutoSimd restore;
  const Fixture fx(1.0);
  std::vector<double> x2(fx.x.size());
  for (std::size_t i = 0; i < x2.size(); ++i) x2[i] = std::sin(0.37 * static_cast<double>(i));
  auto run = [&] {
    std::vector<std::vector<double>> out;
    out.push_back(detect::decimate_half_band(fx.x, 3));
    for (const int spr : {256, 4096}) {  // table path (decimated), polyphase (output above fs)
      detect::ResampleOptions opt;
      opt.samples_per_rev = spr;
      opt.decimation = 1;
      const auto plan = detect::make_angle_plan(fx.pulses, fx.fs, fx.x.size(), opt);
      const auto d1 = detect::decimate_half_band(fx.x, plan.decimation());
      const auto d2 = detect::decimate_half_band(x2, plan.decimation());
      const std::vector<std::span<const double>> xs{d1, d2};
      for (auto& r : detect::resample_by_angle(xs, plan)) out.push_back(r.samples);
    }
    return out;
  };
  ASSERT_TRUE(detect::set_resample_simd(detect::SimdPath::kSse2));
  const auto sse2 = run();
  if (!detect::set_resample_simd(detect::SimdPath::kAvx2)) GTEST_SKIP() << "no AVX2 here";
  const auto avx2 = run();
  ASSERT_EQ(sse2.size(), avx2.size());
  for (std::size_t i = 0; i < sse2.size(); ++i) EXPECT_TRUE(same_bytes(sse2[i], avx2[i])) << i;
}

}  // namespace

namespace {

// max_order returns the lines up to it only: the same bytes as the prefix of the full spectrum.
TEST(OrderSpectrum, MaxOrderReturnsThePrefixOfTheFullSpectrum) {
  detect::AngleResampled r;
  r.samples_per_rev = 64;
  r.revolutions = 40;
  r.samples.resize(64 * 40);
  for (std::size_t m = 0; m < r.samples.size(); ++m)
    r.samples[m] = std::cos(2 * kPi * 5.25 * static_cast<double>(m) / 64) +
                   0.1 * std::sin(0.7 * static_cast<double>(m));
  detect::OrderSpectrumOptions o;
  o.segment_revs = 8;
  const auto full = detect::order_spectrum(r, o);
  o.max_order = 12.3;
  const auto part = detect::order_spectrum(r, o);
  ASSERT_EQ(part.amplitude.size(), static_cast<std::size_t>(12.3 * 8) + 1);
  EXPECT_EQ(part.segments, full.segments);
  for (std::size_t k = 0; k < part.amplitude.size(); ++k) {
    EXPECT_EQ(part.amplitude[k], full.amplitude[k]) << k;
    EXPECT_EQ(part.order[k], full.order[k]) << k;
  }
  o.max_order = -1;
  EXPECT_THROW((void)detect::order_spectrum(r, o), std::exception);
}

}  // namespace
