#include "detect/angular/tacho.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "diag/error.hpp"

namespace {

using detect::TachoOptions;
using detect::TachoRepair;
constexpr double kPi = std::numbers::pi;

// Shaft angle [rev] with constant angular acceleration: phi(t) = phi0 + f0 t + alpha t^2 / 2.
struct Ramp {
  double phi0 = 0, f0 = 0, alpha = 0;
  double revs(double t) const { return phi0 + f0 * t + 0.5 * alpha * t * t; }
  double speed(double t) const { return f0 + alpha * t; }
  // Time at which the angle reaches `revs` (the positive root).
  double time_at(double r) const {
    const double c = phi0 - r;
    if (alpha == 0) return -c / f0;
    return (-f0 + std::sqrt(f0 * f0 - 2 * alpha * c)) / alpha;
  }
  // True times of pulses (angle = k / ppr) inside [0, duration].
  std::vector<double> pulses(double duration, int ppr) const {
    std::vector<double> t;
    for (long k = static_cast<long>(std::ceil(phi0 * ppr));; ++k) {
      const double tk = time_at(static_cast<double>(k) / ppr);
      if (tk > duration) break;
      if (tk >= 0) t.push_back(tk);
    }
    return t;
  }
};

// Our simulator's form: 1 while the pulse is on (the first `duty` of each pulse period), else 0.
std::vector<double> zero_one_train(const Ramp& r, double fs, double duration, int ppr,
                                   double duty) {
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double p = r.revs(n / fs) * ppr;
    x[n] = (p - std::floor(p)) < duty ? 1.0 : 0.0;
  }
  return x;
}

// An ideal 0/1 edge is placed at the midpoint of the two samples that straddle it, so each
// detected time is within half a sampling period of the true edge (plus round-off).
double half_sample(double fs) { return 0.5 / fs + 1e-12; }

TEST(Tacho, ZeroOneTrainAtConstantSpeedGivesEveryEdgeWithinHalfASample) {
  const double fs = 10e3, duration = 4.0;
  const Ramp r{0.37, 25.0, 0.0};  // 1500 rpm
  const auto x = zero_one_train(r, fs, duration, 1, 0.1);
  const auto truth = r.pulses(duration, 1);
  const auto res = detect::tacho_pulses(x, fs);
  ASSERT_EQ(res.pulse_times_s.size(), truth.size());
  EXPECT_TRUE(res.repairs.empty());
  EXPECT_NEAR(res.threshold, 0.5, 1e-12);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(res.pulse_times_s[i], truth[i], half_sample(fs)) << "pulse " << i;
  }
}

// A sine tacho x = sin(2 pi ppr phi(t)) crosses 0 upward at every pulse angle. Linear
// interpolation misplaces a crossing by at most max|x''| T^2 / (8 |x'|) (T = 1/fs), with
// x' = 2 pi ppr f at the crossing and |x''| <= 2 pi ppr alpha + (2 pi ppr f)^3 T within one sample
// of it (the second term: sin grows to 2 pi ppr f T over a sample). The bound is per pulse.
TEST(Tacho, SineTachoOnARunUpIsTimedWithinTheLinearInterpolationBound) {
  const double fs = 20e3, duration = 3.0;
  const int ppr = 2;
  const Ramp r{0.1, 10.0, 20.0};  // 10 -> 70 rev/s
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = std::sin(2 * kPi * ppr * r.revs(n / fs));
  TachoOptions opt;
  opt.pulses_per_rev = ppr;
  opt.threshold = 0.0;
  const auto res = detect::tacho_pulses(x, fs, opt);
  const auto truth = r.pulses(duration, ppr);
  ASSERT_EQ(res.pulse_times_s.size(), truth.size());
  EXPECT_TRUE(res.repairs.empty());
  const double T = 1 / fs;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double w = 2 * kPi * ppr * r.speed(truth[i]);
    const double bound = (2 * kPi * ppr * r.alpha + w * w * w * T) * T * T / (8 * w) + 1e-12;
    EXPECT_NEAR(res.pulse_times_s[i], truth[i], bound) << "pulse " << i;
  }
}

TEST(Tacho, MissedPulseOnARunUpIsInsertedWhereTheAccelerationPutsItAndReported) {
  const double fs = 10e3, duration = 3.0;
  const Ramp r{0.05, 8.0, 30.0};  // 8 -> 98 rev/s
  auto x = zero_one_train(r, fs, duration, 1, 0.2);
  const auto truth = r.pulses(duration, 1);
  // Early in the run-up, where an equal split of the gap would be off by ~alpha / (2 f^3) = 0.9 ms,
  // nine times the tolerance below: the test sees whether the acceleration is used.
  const std::size_t lost = 10;
  // Erase pulse `lost`: zero every sample while that pulse is on.
  for (std::size_t n = 0; n < x.size(); ++n) {
    if (n / fs >= truth[lost] - 1e-9 && n / fs < truth[lost] + 0.5 / r.speed(truth[lost])) x[n] = 0;
  }
  const auto res = detect::tacho_pulses(x, fs);
  ASSERT_EQ(res.repairs.size(), 1u);
  EXPECT_EQ(res.repairs[0].kind, TachoRepair::Kind::kMissedPulse);
  ASSERT_EQ(res.pulse_times_s.size(), truth.size());
  // The inserted time comes from a least-squares quadratic through the four neighbouring edges,
  // each within half a sample; at the gap's middle the fit's weights sum in absolute value to
  // less than 2 (Lebesgue constant of this 4-point fit: 1.67 at constant speed), and the model
  // (constant acceleration) is exact here: bound 2 x half a sample.
  const double kInsertTol = 2 * half_sample(fs);
  EXPECT_NEAR(res.repairs[0].time_s, truth[lost], kInsertTol);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(res.pulse_times_s[i], truth[i], i == lost ? kInsertTol : half_sample(fs)) << i;
  }
}

TEST(Tacho, DoubledPulseIsDroppedAndReported) {
  const double fs = 10e3, duration = 4.0;
  const Ramp r{0.3, 30.0, -3.0};  // run-down 30 -> 18 rev/s
  auto x = zero_one_train(r, fs, duration, 1, 0.1);
  const auto truth = r.pulses(duration, 1);
  // A contact bounce: a second short pulse 30 % into the interval after pulse 40.
  const double t_extra = truth[40] + 0.3 * (truth[41] - truth[40]);
  const auto n0 = static_cast<std::size_t>(std::ceil(t_extra * fs));
  for (std::size_t n = n0; n < n0 + 5; ++n) x[n] = 1.0;
  const auto res = detect::tacho_pulses(x, fs);
  ASSERT_EQ(res.repairs.size(), 1u);
  EXPECT_EQ(res.repairs[0].kind, TachoRepair::Kind::kExtraPulse);
  // The bounce's edge is at the midpoint between sample n0 - 1 and n0.
  EXPECT_NEAR(res.repairs[0].time_s, (n0 - 0.5) / fs, 1e-12);
  ASSERT_EQ(res.pulse_times_s.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(res.pulse_times_s[i], truth[i], half_sample(fs)) << i;
  }
}

TEST(Tacho, WithRepairOffAnomaliesAreReportedAndNothingChanges) {
  const Ramp r{0.0, 10.0, 0.0};
  auto t = r.pulses(5.0, 1);
  t.erase(t.begin() + 20);                          // a missed pulse
  t.insert(t.begin() + 31, 0.5 * (t[30] + t[31]));  // an extra pulse in the middle
  TachoOptions opt;
  opt.repair = false;
  const auto res = detect::repair_pulses(t, opt);
  EXPECT_EQ(res.pulse_times_s, t);
  ASSERT_EQ(res.repairs.size(), 2u);
  EXPECT_EQ(res.repairs[0].kind, TachoRepair::Kind::kMissedPulse);
  EXPECT_EQ(res.repairs[1].kind, TachoRepair::Kind::kExtraPulse);
}

TEST(Tacho, IntervalThatFitsNoRepairIsReportedAsIrregular) {
  const Ramp r{0.0, 10.0, 0.0};
  auto t = r.pulses(5.0, 1);
  // 1.6 median intervals: neither a normal interval nor two (tolerance 0.3).
  for (std::size_t i = 25; i < t.size(); ++i) t[i] += 0.06;
  const auto res = detect::repair_pulses(t);
  ASSERT_EQ(res.repairs.size(), 1u);
  EXPECT_EQ(res.repairs[0].kind, TachoRepair::Kind::kIrregularInterval);
  EXPECT_DOUBLE_EQ(res.repairs[0].time_s, t[24]);
  EXPECT_EQ(res.pulse_times_s, t);
}

TEST(Tacho, AutoThresholdIgnoresIsolatedSpikes) {
  const double fs = 5e3;
  const Ramp r{0.2, 12.0, 0.0};
  auto x = zero_one_train(r, fs, 3.0, 1, 0.25);
  const auto clean = detect::tacho_pulses(x, fs);
  for (std::size_t n : {1000u, 4000u, 9000u}) x[n] = 50.0;
  const auto spiky = detect::tacho_pulses(x, fs);
  EXPECT_DOUBLE_EQ(spiky.threshold, clean.threshold);
  // A spike during the off time adds an edge, which the repair step must catch as an extra pulse.
  EXPECT_EQ(spiky.pulse_times_s.size(), clean.pulse_times_s.size());
}

TEST(Tacho, FlatSignalGivesNoPulsesNotAnError) {
  const std::vector<double> x(1000, 0.25);
  const auto res = detect::tacho_pulses(x, 1e3);
  EXPECT_TRUE(res.pulse_times_s.empty());
}

// rpm over a window is exact for a linear speed: the mean of a linear function over an interval
// is its value at the midpoint. Only round-off remains (1e-9 relative).
TEST(SpeedProfile, IsExactForConstantAcceleration) {
  const Ramp r{0.0, 15.0, 4.0};
  const int ppr = 3;
  const auto t = r.pulses(4.0, ppr);
  for (int w : {1, 3, 7}) {
    const auto sp = detect::speed_profile(t, ppr, w);
    ASSERT_EQ(sp.rpm.size(), t.size() - w);
    for (std::size_t j = 0; j < sp.rpm.size(); ++j) {
      EXPECT_NEAR(sp.rpm[j], 60 * r.speed(sp.time_s[j]), 1e-9 * sp.rpm[j]) << "w " << w;
    }
  }
}

TEST(Tacho, BadOptionsNameTheField) {
  auto expect_field = [](TachoOptions o, const char* field) {
    try {
      o.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const diag::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  TachoOptions o;
  o.pulses_per_rev = 0;
  expect_field(o, "pulses_per_rev");
  o = {};
  o.repair_tolerance = 0.6;
  expect_field(o, "repair_tolerance");
  o = {};
  o.median_window = 4;
  expect_field(o, "median_window");
  o = {};
  o.hysteresis_fraction = -0.1;
  expect_field(o, "hysteresis_fraction");
  const std::vector<double> x(10, 0.0);
  EXPECT_THROW(detect::tacho_pulses(x, 0.0), diag::InputError);
  const std::vector<double> bad_times{0.0, 0.2, 0.1};
  EXPECT_THROW(detect::repair_pulses(bad_times), diag::InputError);
}

}  // namespace
