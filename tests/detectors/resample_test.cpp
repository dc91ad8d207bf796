#include "detect/angular/resample.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <numbers>
#include <random>
#include <span>
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

// ---------------------------------------------------------------------------------------------
// The AnglePlan against the documented formula, evaluated naively (std::cyl_bessel_i per tap).

// The documented formula for output m of a plan, from the public ShaftAngle model:
//   y_m = sum_n x[n] g sinc(g (u - n)) w((u - n) / K), u = time_at(theta_m) fs, K = Z / g,
//   g = 2 min(spr f / 2, fs / 2) / (1 + delta / 2) / fs, f = max(speed, mean speed / 10),
//   delta = (80 - 8) / (2.285 2 pi Z) (Kaiser's width formula, ~5 / Z), w Kaiser with
//   beta = 0.1102 (80 - 8.7).
double naive_output(std::span<const double> x, double fs, const detect::ShaftAngle& a,
                    const detect::ResampleOptions& o, double theta, double* u_out, double* g_out) {
  const int z = o.kernel_zero_crossings;
  const double beta = 0.1102 * (80.0 - 8.7);
  const double delta = (80.0 - 8.0) / (2.285 * 2 * kPi * z);
  const double t = a.time_at(theta);
  const double floor = 0.1 * a.total_revs() / (a.last_pulse_s() - a.first_pulse_s());
  const double f = std::max(a.speed_rev_per_s(t), floor);
  const double g = 2 * std::min(o.samples_per_rev * f / 2, fs / 2) / (1 + delta / 2) / fs;
  const double u = t * fs, k_half = z / g;
  double acc = 0;
  for (long n = std::max<long>(0, static_cast<long>(std::ceil(u - k_half)));
       n <= std::min<long>(static_cast<long>(x.size()) - 1, static_cast<long>(u + k_half)); ++n) {
    const double d = u - static_cast<double>(n);
    const double r = d / k_half;
    if (std::abs(r) >= 1) continue;
    const double sinc = d == 0 ? 1.0 : std::sin(kPi * g * d) / (kPi * g * d);
    const double w =
        std::cyl_bessel_i(0.0, beta * std::sqrt(1 - r * r)) / std::cyl_bessel_i(0.0, beta);
    acc += x[static_cast<std::size_t>(n)] * g * sinc * w;
  }
  *u_out = u;
  *g_out = g;
  return acc;
}

std::vector<double> white_noise(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::vector<double> x(n);
  for (double& v : x) v = gauss(rng);
  return x;
}

// The table's only approximation is the kernel's cubic interpolation, at most 3.1e-9 of its peak
// per tap for Z = 16 (resample.hpp). A tap error e moves y_m by at most g sum_n |x[n]| e <=
// 2 Z e max|x|, i.e. 1e-7 x max|x|; white noise (max ~ 4.5 RMS here) bounds it by 4.5e-7 RMS:
// kRelTol = 1e-6 of the RMS. The plan's times come from a warm-started Newton on the same
// Hermite model as time_at: kPositionTol = 1e-9 samples (round-off of u ~ 2e5 is 3e-11);
// kCutoffTol: the speed from the same segment, 1e-12 relative.
void expect_plan_matches_formula(const Ramp& ramp, double fs, double duration, int spr, int ppr) {
  const auto p = ramp.pulses(duration, ppr);
  const auto x = white_noise(static_cast<std::size_t>(duration * fs), 11);
  detect::ResampleOptions o;
  o.samples_per_rev = spr;
  o.pulses_per_rev = ppr;
  const detect::ShaftAngle a(p, ppr);
  const auto plan = detect::make_angle_plan(a, fs, x.size(), o);
  const auto y = detect::resample_by_angle(x, plan);
  constexpr double kRelTol = 1e-6, kPositionTol = 1e-9, kCutoffTol = 1e-12;
  ASSERT_EQ(y.samples.size(), plan.size());
  double worst = 0;
  for (std::size_t m = 0; m < y.samples.size(); m += 5) {
    double u = 0, g = 0;
    const double want =
        naive_output(x, fs, a, o, y.first_rev + static_cast<double>(m) / spr, &u, &g);
    ASSERT_NEAR(plan.positions()[m], u, kPositionTol) << m;
    ASSERT_NEAR(plan.cutoffs()[m], g, kCutoffTol * g) << m;
    worst = std::max(worst, std::abs(y.samples[m] - want));
  }
  EXPECT_LT(worst, kRelTol) << "(x has unit RMS)";
  std::cout << "  worst |fast - formula| = " << worst << " x RMS over " << y.samples.size() / 5
            << " outputs\n";
  // The one-call form builds the same plan: the same bytes.
  const auto direct = detect::resample_by_angle(x, fs, p, o);
  EXPECT_EQ(direct.samples, y.samples);
  EXPECT_EQ(direct.first_rev, y.first_rev);
  EXPECT_EQ(direct.revolutions, y.revolutions);
}

TEST(AnglePlan, EqualsTheDocumentedFormulaAtConstantSpeed) {
  expect_plan_matches_formula(Ramp{0.3, 37.0, 0.0}, 20e3, 1.5, 64, 1);
}

// Run-up 10 -> 40 rev/s with 3 pulses per revolution and 256 samples per revolution: the cutoff
// reaches fs / 2 (the kernel's g is capped) in the second half.
TEST(AnglePlan, EqualsTheDocumentedFormulaOnARunUp) {
  expect_plan_matches_formula(Ramp{0.1, 10.0, 20.0}, 10e3, 1.5, 256, 3);
}

// One cutoff at every output makes the plan take its taps from the polyphase table
// (resample.hpp): a steady speed (37 rev/s x 512 samples/rev, below fs), or a speed whose angular
// Nyquist lies above fs / 2 all along (37 -> 37.75 rev/s x 1024: the cutoff is fs / 2). The
// stated bound: an output within 3.3e-6 of max|x| of the formula (the table's 3.1e-9 and the
// quadratic's 3.6e-9 per tap over 2 (K + 1) taps, the kink's 1.5e-6 at two taps); white noise of
// unit RMS has max|x| < 5.5 over 3e4 samples: kTol = 3.3e-6 x 5.5. The slow ramp at 512
// samples/rev (the cutoff follows the speed: per-tap table) is the control.
TEST(AnglePlan, PolyphaseTapsAreWithinTheirStatedErrorOfTheFormula) {
  const double fs = 20e3, duration = 1.5;
  const auto x = white_noise(static_cast<std::size_t>(duration * fs), 5);
  const double max_x = std::abs(*std::max_element(
      x.begin(), x.end(), [](double a, double b) { return std::abs(a) < std::abs(b); }));
  ASSERT_LT(max_x, 5.5);
  constexpr double kTol = 3.3e-6 * 5.5;
  struct Case {
    Ramp ramp;
    int spr;
    bool polyphase;
  };
  for (const Case& c :
       {Case{Ramp{0.3, 37.0, 0.0}, 512, true}, Case{Ramp{0.3, 37.0, 0.5}, 1024, true},
        Case{Ramp{0.3, 37.0, 0.5}, 512, false}}) {
    const auto p = c.ramp.pulses(duration);
    detect::ResampleOptions o;
    o.samples_per_rev = c.spr;
    const detect::ShaftAngle a(p, 1);
    const auto plan = detect::make_angle_plan(a, fs, x.size(), o);
    EXPECT_EQ(plan.polyphase(), c.polyphase) << c.spr;
    const auto y = detect::resample_by_angle(x, plan);
    double worst = 0;
    for (std::size_t m = 0; m < y.samples.size(); m += 11) {
      double u = 0, g = 0;
      const double want =
          naive_output(x, fs, a, o, y.first_rev + static_cast<double>(m) / c.spr, &u, &g);
      worst = std::max(worst, std::abs(y.samples[m] - want));
    }
    EXPECT_LT(worst, kTol) << c.spr;
    std::cout << "  " << c.spr << " samples/rev, " << (c.polyphase ? "polyphase" : "per-tap table")
              << ": worst |fast - formula| = " << worst << " (max|x| " << max_x << ")\n";
  }
}

// The table against the formula sinc(v) w(v / Z) over [0, Z] (v on and between the table's
// points), within the cubic Hermite bound h(0) / (384 x 64^4) (resample.hpp): h(0) =
// pi^4 / 5 + 2 pi^2 beta I1(beta) / (I0(beta) Z^2) + 3 beta^2 I2(beta) / (I0(beta) Z^4), from the
// Taylor series of the sinc and of the window in (v / Z)^2; 4.5e-9 at Z = 4, 3.0e-9 at Z = 64.
TEST(AnglePlan, KernelTableIsWithinItsStatedErrorOfTheFormula) {
  const std::vector<double> p{0.2, 0.3, 0.4, 0.5, 0.6};
  const double beta = 0.1102 * (80.0 - 8.7);
  const double i0 = std::cyl_bessel_i(0.0, beta), i1 = std::cyl_bessel_i(1.0, beta),
               i2 = std::cyl_bessel_i(2.0, beta);
  for (int z : {4, 16, 64}) {
    detect::ResampleOptions o;
    o.kernel_zero_crossings = z;
    o.samples_per_rev = 64;
    const auto plan = detect::make_angle_plan(p, 1e3, 1000, o);
    const double z2 = static_cast<double>(z) * z;
    const double d4 = std::pow(kPi, 4) / 5 + 2 * kPi * kPi * beta * i1 / (i0 * z2) +
                      3 * beta * beta * i2 / (i0 * z2 * z2);
    const double table_tol = d4 / (384 * std::pow(64.0, 4));
    double worst = 0;
    for (double v = 0; v <= z; v += 1.0 / 1000) {
      const double r = v / z;
      const double want = (v == 0 ? 1.0 : std::sin(kPi * v) / (kPi * v)) *
                          std::cyl_bessel_i(0.0, beta * std::sqrt(std::max(0.0, 1 - r * r))) / i0;
      worst = std::max(worst, std::abs(plan.kernel(v) - want));
    }
    EXPECT_LT(worst, table_tol) << "Z = " << z;
    std::cout << "  Z = " << z << ": worst table error " << worst << " (bound " << table_tol
              << ")\n";
  }
}

// A plan that keeps its taps gives the same bytes as one that computes them on every application
// (both cutoff paths: a run-up, the per-tap table; a steady speed, the polyphase table), keeps
// them from its first application (copies share them), and keeps none above its limit.
TEST(AnglePlan, KeptTapsGiveTheSameBytes) {
  const double fs = 8e3, duration = 2.0;
  const auto a = white_noise(static_cast<std::size_t>(duration * fs), 3);
  const auto b = white_noise(static_cast<std::size_t>(duration * fs), 4);
  for (const Ramp& r : {Ramp{0.25, 20.0, 8.0}, Ramp{0.25, 20.0, 0.0}}) {
    detect::ResampleOptions o;
    o.samples_per_rev = 128;
    const auto p = r.pulses(duration);
    const auto plain = detect::make_angle_plan(p, fs, a.size(), o);
    auto keeping = plain;
    keeping.keep_taps(std::size_t{1} << 22);
    const auto copy = keeping;
    EXPECT_EQ(keeping.kept_taps(), 0u);
    EXPECT_EQ(detect::resample_by_angle(a, keeping).samples,
              detect::resample_by_angle(a, plain).samples);
    EXPECT_GT(copy.kept_taps(), keeping.size());  // several taps per output, shared by the copy
    EXPECT_EQ(detect::resample_by_angle(b, copy).samples,
              detect::resample_by_angle(b, plain).samples);
    const std::vector<std::span<const double>> both{a, b};
    const auto together = detect::resample_by_angle(both, keeping);
    EXPECT_EQ(together[1].samples, detect::resample_by_angle(b, plain).samples);
    auto small = plain;
    small.keep_taps(keeping.kept_taps() - 1);
    EXPECT_EQ(detect::resample_by_angle(a, small).samples,
              detect::resample_by_angle(a, plain).samples);
    EXPECT_EQ(small.kept_taps(), 0u);
  }
}

TEST(AnglePlan, AppliedToTwoChannelsEqualsTwoSeparateCalls) {
  const Ramp r{0.25, 20.0, 8.0};
  const double fs = 8e3, duration = 2.0;
  const auto p = r.pulses(duration);
  const auto a = white_noise(static_cast<std::size_t>(duration * fs), 1);
  const auto b = white_noise(static_cast<std::size_t>(duration * fs), 2);
  detect::ResampleOptions o;
  o.samples_per_rev = 128;
  const auto plan = detect::make_angle_plan(p, fs, a.size(), o);
  const std::vector<std::span<const double>> both{a, b};
  const auto together = detect::resample_by_angle(both, plan);
  ASSERT_EQ(together.size(), 2u);
  EXPECT_EQ(together[0].samples, detect::resample_by_angle(a, plan).samples);
  EXPECT_EQ(together[1].samples, detect::resample_by_angle(b, fs, p, o).samples);
  EXPECT_EQ(together[1].first_rev, plan.first_rev());
  EXPECT_EQ(together[1].revolutions, plan.revolutions());
  EXPECT_EQ(together[1].samples_per_rev, 128);
}

TEST(AnglePlan, BadInputsNameTheField) {
  const std::vector<double> x(1000, 0.0);
  const std::vector<double> p{0.1, 0.2, 0.3, 0.4, 0.5};
  detect::ResampleOptions o;
  o.samples_per_rev = 16;
  const auto plan = detect::make_angle_plan(p, 1e3, x.size(), o);
  const std::vector<double> shorter(999, 0.0);
  EXPECT_THROW(detect::resample_by_angle(shorter, plan), diag::InputError);
  std::vector<double> nan = x;
  nan[500] = std::nan("");
  EXPECT_THROW(detect::resample_by_angle(nan, plan), diag::InputError);
  const detect::ShaftAngle two_per_rev(p, 2);
  try {
    detect::make_angle_plan(two_per_rev, 1e3, x.size(), o);
    ADD_FAILURE() << "accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pulses_per_rev"), std::string::npos) << e.what();
  }
  EXPECT_THROW(detect::make_angle_plan(p, 0.0, x.size(), o), diag::InputError);
}

// The incremental inverse equals time_at() and speed_rev_per_s() where the limiter acts too
// (an abrupt 10 -> 67 rev/s step) and beyond the pulses (linear extrapolation).
TEST(ShaftAngle, UniformAnglesWalkEqualsTimeAt) {
  std::vector<double> p;
  double t = 0;
  for (int i = 0; i < 40; ++i) p.push_back(t += (i < 20 ? 0.1 : 0.015));
  const detect::ShaftAngle a(p, 2);
  const int spr = 37;
  std::vector<double> times(static_cast<std::size_t>(22 * spr)), speeds(times.size());
  a.times_at_uniform_angles(-0.5, spr, times, speeds);
  constexpr double kTimeTol = 1e-14;  // s: the Newton stops within a few ulps of s in [0, 1]
  for (std::size_t m = 0; m < times.size(); ++m) {
    const double revs = -0.5 + static_cast<double>(m) / spr;
    ASSERT_NEAR(times[m], a.time_at(revs), kTimeTol) << m;
    ASSERT_NEAR(speeds[m], a.speed_rev_per_s(times[m]), 1e-9 * speeds[m]) << m;
  }
}

}  // namespace
