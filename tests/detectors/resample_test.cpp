#include "detect/angular/resample.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "detect/angular/order_spectrum.hpp"
#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

// Shaft angle [rev] with constant angular acceleration from t = 0.
struct Ramp {
  double phi0 = 0, f0 = 0, alpha = 0;
  double revs(double t) const { return phi0 + f0 * t + 0.5 * alpha * t * t; }
  double speed(double t) const { return f0 + alpha * t; }
  double time_at(double r) const {
    const double c = phi0 - r;
    if (alpha == 0) return -c / f0;
    return (-f0 + std::sqrt(f0 * f0 - 2 * alpha * c)) / alpha;
  }
  std::vector<double> pulses(double duration, int ppr = 1) const {
    std::vector<double> t;
    for (long k = static_cast<long>(std::ceil(phi0 * ppr));; ++k) {
      const double tk = time_at(static_cast<double>(k) / ppr);
      if (tk > duration) break;
      if (tk >= 0) t.push_back(tk);
    }
    return t;
  }
};

// Angle from the first pulse, which is where ShaftAngle puts zero.
double revs_from_first_pulse(const Ramp& r, const std::vector<double>& pulses, double t) {
  return r.revs(t) - r.revs(pulses.front());
}

// The three-point slope of a parabola is exact, so the Hermite model reproduces a constant
// acceleration to round-off (1e-12 rev over a few hundred revolutions).
TEST(ShaftAngle, IsExactForConstantAngularAcceleration) {
  const Ramp r{0.21, 12.0, 7.0};
  const auto p = r.pulses(6.0, 3);
  const detect::ShaftAngle a(p, 3);
  constexpr double kAngleTol = 1e-10;  // rev
  for (double t = p.front(); t <= p.back(); t += 0.0137) {
    EXPECT_NEAR(a.revs_at(t), revs_from_first_pulse(r, p, t), kAngleTol) << t;
    EXPECT_NEAR(a.speed_rev_per_s(t), r.speed(t), 1e-8 * r.speed(t)) << t;
    EXPECT_NEAR(a.time_at(a.revs_at(t)), t, 1e-12) << t;
  }
  EXPECT_NEAR(a.total_revs(), (p.size() - 1) / 3.0, 1e-15);
}

TEST(ShaftAngle, NeverRunsBackwardsAfterAnAbruptSpeedChange) {
  std::vector<double> p;
  double t = 0;
  for (int i = 0; i < 40; ++i) p.push_back(t += (i < 20 ? 0.1 : 0.015));  // 10 -> 67 rev/s
  const detect::ShaftAngle a(p);
  double prev = a.revs_at(p.front());
  for (double s = p.front(); s <= p.back(); s += 1e-4) {
    const double v = a.revs_at(s);
    EXPECT_GE(v, prev - 1e-15) << s;
    prev = v;
  }
}

// A speed ratio that is an integer fraction lands B's revolutions on A's pulses exactly; a
// non-integer ratio (49/51, a gear pair) puts them between A's pulses where the exact constant
// acceleration model says (round-off: 1e-11 s).
TEST(ScalePulses, PlacesTheOtherShaftsRevolutionsOnItsAngle) {
  const Ramp r{0.0, 20.0, 6.0};
  const auto a = r.pulses(5.0);
  const auto half = detect::scale_pulses(a, 0.5);
  ASSERT_EQ(half.size(), (a.size() - 1) / 2 + 1);
  for (std::size_t k = 0; k < half.size(); ++k) EXPECT_NEAR(half[k], a[2 * k], 1e-11);

  const double ratio = 49.0 / 51.0;
  const auto b = detect::scale_pulses(a, ratio);
  EXPECT_EQ(b.size(), static_cast<std::size_t>(std::floor(ratio * (a.size() - 1))) + 1);
  for (std::size_t k = 0; k < b.size(); ++k) {
    EXPECT_NEAR(b[k], r.time_at(k / ratio), 1e-11) << k;
  }
  EXPECT_THROW(detect::scale_pulses(a, 0.0), diag::InputError);
}

// Amplitude of order `q` in the whole resampled record, by a naive DFT at that order (a
// reference independent of the FFT and of the order-spectrum code).
double naive_order_amplitude(const detect::AngleResampled& y, double q) {
  std::complex<double> acc = 0;
  for (std::size_t m = 0; m < y.samples.size(); ++m) {
    acc += y.samples[m] * std::polar(1.0, -2 * kPi * q * m / y.samples_per_rev);
  }
  return 2 * std::abs(acc) / static_cast<double>(y.samples.size());
}

// Passband and stopband of the speed-tracking filter, at constant speed: 50 rev/s, 64 samples per
// revolution (Nyquist order 32). An order in the passband (20 = 0.63 x Nyquist, below the
// documented 0.72) keeps its amplitude to the Kaiser ripple (80 dB design: 1e-4; allow 5e-4, as
// Kaiser's width formula is an estimate); orders above the Nyquist that would alias onto orders
// 28 and 20 (orders 36 and 44) come out below 2e-4 (-74 dB: the 80 dB design, 6 dB of margin for
// the same reason).
TEST(Resample, PassesOrdersBelowAndStopsOrdersAboveTheAngularNyquist) {
  const double fs = 20e3, duration = 3.0;
  const Ramp r{0.4, 50.0, 0.0};
  const auto p = r.pulses(duration);
  detect::ResampleOptions opt;
  opt.samples_per_rev = 64;
  constexpr double kPassTol = 5e-4, kStopTol = 2e-4;
  auto run = [&](double order) {
    std::vector<double> x(static_cast<std::size_t>(duration * fs));
    for (std::size_t n = 0; n < x.size(); ++n) x[n] = std::cos(2 * kPi * order * r.revs(n / fs));
    return detect::resample_by_angle(x, fs, p, opt);
  };
  const auto pass = run(20.0);
  EXPECT_NEAR(naive_order_amplitude(pass, 20.0), 1.0, kPassTol);
  // Sample by sample too: y_m = cos(2 pi 20 phi(theta_m)).
  const double phase0 = r.revs(p.front());
  double worst = 0;
  for (std::size_t m = 0; m < pass.samples.size(); ++m) {
    const double theta = pass.first_rev + static_cast<double>(m) / 64 + phase0;
    worst = std::max(worst, std::abs(pass.samples[m] - std::cos(2 * kPi * 20.0 * theta)));
  }
  EXPECT_LT(worst, kPassTol);
  EXPECT_LT(naive_order_amplitude(run(36.0), 28.0), kStopTol);
  EXPECT_LT(naive_order_amplitude(run(44.0), 20.0), kStopTol);
}

// The reason for order tracking: order 27 of a shaft running up 10 -> 90 rev/s sweeps 270 ->
// 2430 Hz, so an ordinary spectrum spreads it over ~17000 lines (its peak, by stationary phase,
// ~ a / sqrt(duration x sweep rate) = a / 46), while the order spectrum of the resampled signal
// holds it on one line at order 27 with its amplitude: the only error is the resampling
// passband ripple (kAmpTol = 5e-4, as above). With a Hann window an order on a
// line leaks only into the two adjacent lines, so 99.9 % of the power lies within +-1 line.
TEST(OrderSpectrum, ConstantOrderOnARunUpIsASharpLineAtItsOrderWithItsAmplitude) {
  const double fs = 20e3, duration = 8.0, a = 1.3;
  const Ramp r{0.15, 10.0, 10.0};
  const auto p = r.pulses(duration);
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n)
    x[n] = a * std::cos(2 * kPi * 27 * r.revs(n / fs) + 0.3);

  // Ordinary spectrum (Hann, whole record): smeared.
  detect::RealFft fft(x.size());
  std::vector<double> xw(x.size());
  double wsum = 0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double w = 0.5 - 0.5 * std::cos(2 * kPi * n / x.size());
    xw[n] = x[n] * w;
    wsum += w;
  }
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(xw, X);
  double peak_hz_amp = 0;
  for (const auto& v : X) peak_hz_amp = std::max(peak_hz_amp, 2 * std::abs(v) / wsum);
  EXPECT_LT(peak_hz_amp, 0.1 * a);

  detect::ResampleOptions ro;
  ro.samples_per_rev = 128;
  const auto y = detect::resample_by_angle(x, fs, p, ro);
  const auto os = detect::order_spectrum(y);
  ASSERT_EQ(os.segments, 1);
  const auto peak =
      std::max_element(os.amplitude.begin(), os.amplitude.end()) - os.amplitude.begin();
  EXPECT_DOUBLE_EQ(os.order[static_cast<std::size_t>(peak)], 27.0);
  constexpr double kAmpTol = 5e-4;
  EXPECT_NEAR(os.amplitude[static_cast<std::size_t>(peak)], a, kAmpTol * a);
  double total = 0, near = 0;
  for (std::size_t k = 0; k < os.amplitude.size(); ++k) {
    const double pw = os.amplitude[k] * os.amplitude[k];
    total += pw;
    if (std::abs(os.order[k] - 27.0) <= 1.01 * os.resolution_order) near += pw;
  }
  EXPECT_GT(near / total, 0.999);
}

// Segment averaging: the amplitude of an order on a line is the same for every segment length
// (power average of equal amplitudes), and the line spacing is 1 / segment_revs.
TEST(OrderSpectrum, SegmentAveragingKeepsTheAmplitudeOfAnOrderOnALine) {
  const double fs = 8e3, duration = 6.0;
  const Ramp r{0.0, 20.0, 3.0};
  const auto p = r.pulses(duration);
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = 0.7 * std::sin(2 * kPi * 5 * r.revs(n / fs));
  detect::ResampleOptions ro;
  ro.samples_per_rev = 32;
  const auto y = detect::resample_by_angle(x, fs, p, ro);
  for (int seg : {4, 8, 16}) {
    detect::OrderSpectrumOptions oo;
    oo.segment_revs = seg;
    const auto os = detect::order_spectrum(y, oo);
    EXPECT_GT(os.segments, 1);
    EXPECT_DOUBLE_EQ(os.resolution_order, 1.0 / seg);
    EXPECT_NEAR(os.amplitude[static_cast<std::size_t>(5 * seg)], 0.7, 5e-4 * 0.7) << seg;
  }
}

// A constant stays constant: the kernel's DC gain is 1 to the passband ripple.
TEST(Resample, ConstantSignalStaysConstantAndWholeRevolutionsAreReturned) {
  const double fs = 5e3;
  const Ramp r{0.6, 15.0, 2.0};
  const auto p = r.pulses(4.0, 2);
  const std::vector<double> x(static_cast<std::size_t>(4.0 * fs), 2.5);
  detect::ResampleOptions ro;
  ro.samples_per_rev = 100;
  ro.pulses_per_rev = 2;
  const auto y = detect::resample_by_angle(x, fs, p, ro);
  EXPECT_EQ(y.samples.size(), static_cast<std::size_t>(y.revolutions) * 100);
  EXPECT_EQ(y.first_rev, std::floor(y.first_rev));
  EXPECT_GE(y.revolutions, static_cast<int>((p.size() - 1) / 2) - 2);
  for (double v : y.samples) EXPECT_NEAR(v, 2.5, 5e-4 * 2.5);
}

TEST(Resample, BadInputsNameTheField) {
  const std::vector<double> x(1000, 0.0);
  const std::vector<double> p{0.1, 0.2, 0.3};
  detect::ResampleOptions o;
  o.samples_per_rev = 4;
  EXPECT_THROW(detect::resample_by_angle(x, 1e3, p, o), diag::InputError);
  o = {};
  o.kernel_zero_crossings = 2;
  EXPECT_THROW(detect::resample_by_angle(x, 1e3, p, o), diag::InputError);
  EXPECT_THROW(detect::resample_by_angle(x, -1.0, p, {}), diag::InputError);
  const std::vector<double> unordered{0.1, 0.3, 0.2};
  EXPECT_THROW(detect::resample_by_angle(x, 1e3, unordered, {}), diag::InputError);
  // Pulses at the very ends leave no room for the filter.
  const std::vector<double> edge{0.0, 0.999};
  try {
    detect::resample_by_angle(x, 1e3, edge, {});
    ADD_FAILURE() << "accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("margin"), std::string::npos) << e.what();
  }
}

}  // namespace
