// analyze's tacho smoothing for the order domain (detectors/src/analysis/kinematics.hpp,
// smooth_pulse_times_local_quadratic): a local quadratic least-squares fit of the pulse times t(k).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../../detectors/src/analysis/kinematics.hpp"

namespace {

// Pulse times of a constant acceleration from f0 [rev/s] by a [rev/s^2]: the k-th revolution at
// t = (sqrt(f0^2 + 2 a k) - f0) / a.
std::vector<double> run_up_pulses(double f0, double a, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    t[static_cast<std::size_t>(k)] = (std::sqrt(f0 * f0 + 2 * a * k) - f0) / a;
  return t;
}

// A parabola t(k) is reproduced by the fit, ends included (the window shifted inward there).
// Tolerance: round-off of the normal equations over 21 points, 1e-12 s on times of ~10 s.
TEST(AnalyzeKinematics, SmoothedPulsesKeepAQuadraticExactly) {
  std::vector<double> t(300);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double x = static_cast<double>(k);
    t[k] = 0.05 + 0.02 * x + 1e-5 * x * x;
  }
  const auto s = detect::smooth_pulse_times_local_quadratic(t, 10);
  ASSERT_EQ(s.size(), t.size());
  for (std::size_t k = 0; k < t.size(); ++k) EXPECT_NEAR(s[k], t[k], 1e-12) << k;
}

// Uniform timing jitter of +-T/2 (a sharp tacho edge sampled at 1/T) on a run-up: inside the
// record the fit's error RMS is the jitter's times the Savitzky-Golay centre gain of a quadratic
// over 2m + 1 points, sqrt(3 (3m^2 + 3m - 1) / ((2m - 1)(2m + 1)(2m + 3))) = 0.328 for m = 10
// (the run-up's own curvature is far below the jitter: its third derivative over the window is
// ~1e-9 s). Tolerance 10 %: 4000 interior points, neighbouring errors correlated over 21.
TEST(AnalyzeKinematics, SmoothedPulsesReduceTheJitterByTheFitsGain) {
  const auto truth = run_up_pulses(500.0 / 60, 2500.0 / 60 / 9, 4100);
  constexpr double kT = 1e-4;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-kT / 2, kT / 2);
  std::vector<double> t = truth;
  for (double& x : t) x += jitter(rng);
  const auto s = detect::smooth_pulse_times_local_quadratic(t, 10);
  double e2 = 0;
  int n = 0;
  for (std::size_t k = 50; k + 50 < t.size(); ++k, ++n) e2 += (s[k] - truth[k]) * (s[k] - truth[k]);
  const double m = 10;
  const double gain =
      std::sqrt(3 * (3 * m * m + 3 * m - 1) / ((2 * m - 1) * (2 * m + 1) * (2 * m + 3)));
  EXPECT_NEAR(std::sqrt(e2 / n), gain * kT / std::sqrt(12.0), 0.1 * gain * kT / std::sqrt(12.0));
}

TEST(AnalyzeKinematics, FewerPulsesThanTheWindowAreReturnedAsGiven) {
  const std::vector<double> t{0.0, 0.1, 0.25};
  EXPECT_EQ(detect::smooth_pulse_times_local_quadratic(t, 10), t);
  EXPECT_EQ(detect::smooth_pulse_times_local_quadratic(t, 0), t);
}

}  // namespace
