// Kahraman & Singh single-DOF gear pair with backlash: the linear closed form, the softening
// primary resonance with jumps and hysteresis, contact loss and back-flank impacts, and the
// super-harmonic resonance near Omega = 1/2 that time-varying stiffness creates.
#include "sim/dynamics/sdof_backlash.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "diag/error.hpp"

namespace {

using sim::SdofBacklashOptions;
using sim::SdofResponse;

// The papers' parameters (zeta 0.05, F_m 0.1), time-invariant stiffness (1990 paper) and a
// transmission-error excitation F_1 = 0.05: the linear resonance amplitude F_1 / (2 zeta) = 0.5
// is 5x the mean deflection, so the teeth separate near resonance.
SdofBacklashOptions time_invariant() {
  SdofBacklashOptions o;
  o.stiffness = {};
  o.transmission_error = {{0.05, 0.0}};
  return o;
}

// Steady-state amplitude of x'' + 2 zeta x' + x = F Omega^2 cos(Omega tau).
double linear_amplitude(double f, double zeta, double omega) {
  const double d = 1.0 - omega * omega;
  return f * omega * omega / std::sqrt(d * d + 4.0 * zeta * zeta * omega * omega);
}

template <class F>
std::string input_error_message(F&& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "(no InputError thrown)";
}

// Index of the largest |rms[i+1] - rms[i]| along a branch, and its sign.
struct Jump {
  std::size_t index = 0;  // between branch[index] and branch[index + 1]
  double change = 0.0;
};
Jump largest_jump(const std::vector<SdofResponse>& branch) {
  Jump j;
  for (std::size_t i = 0; i + 1 < branch.size(); ++i) {
    const double c = branch[i + 1].rms - branch[i].rms;
    if (std::abs(c) > std::abs(j.change)) j = {i, c};
  }
  return j;
}

// RK4 at >= 256 steps per period, h <= 2 pi / (256 Omega): local error ~ h^5 / 120 <= 3e-8 at
// Omega = 0.3, global error of the forced response of the same order; the sampled RMS of a
// sinusoid over whole periods is exact; transients have decayed by exp(-zeta 2 pi 300 / Omega)
// < 1e-25. 1e-6 leaves a margin of ~30 over the measured error.
constexpr double kLinearRelTol = 1e-6;

TEST(SdofBacklash, WithoutBacklashMatchesTheLinearClosedForm) {
  SdofBacklashOptions o = time_invariant();
  o.half_backlash = 0.0;  // f(x) = x
  const auto sweep = sim::sdof_sweep(o, 0.3, 1.6, 14);
  for (const auto* branch : {&sweep.up, &sweep.down}) {
    for (const SdofResponse& r : *branch) {
      const double amp = linear_amplitude(0.05, 0.05, r.omega);
      EXPECT_NEAR(r.rms, amp / std::sqrt(2.0), kLinearRelTol * amp) << "Omega " << r.omega;
      EXPECT_NEAR(r.mean, o.mean_load, kLinearRelTol * amp) << "Omega " << r.omega;
    }
  }
}

TEST(SdofBacklash, LargeMeanLoadKeepsContactAndMatchesTheShiftedLinearSolution) {
  // F_m = 1 > the largest amplitude (0.5 at resonance): the drive flank never separates, so
  // f(x) = x - 1 throughout and x = 1 + F_m + linear response.
  SdofBacklashOptions o = time_invariant();
  o.mean_load = 1.0;
  const auto sweep = sim::sdof_sweep(o, 0.5, 1.5, 11);
  for (const SdofResponse& r : sweep.up) {
    const double amp = linear_amplitude(0.05, 0.05, r.omega);
    EXPECT_NEAR(r.rms, amp / std::sqrt(2.0), kLinearRelTol * amp) << "Omega " << r.omega;
    EXPECT_NEAR(r.mean, 2.0, kLinearRelTol * amp) << "Omega " << r.omega;
    EXPECT_FALSE(r.contact_lost) << "Omega " << r.omega;
    EXPECT_EQ(r.separated_fraction, 0.0);
  }
}

// The classic result of both papers: contact loss makes the primary resonance softening (the
// effective stiffness drops while the teeth are apart), so the peak leans to Omega < 1, the run
// up jumps UP onto the resonant branch at a higher Omega than the run down jumps DOWN off it,
// and in between two stable responses coexist.
TEST(SdofBacklash, PrimaryResonanceIsSofteningWithJumpsAndHysteresis) {
  for (double alpha : {0.0, 0.2}) {
    SCOPED_TRACE("alpha_1 = " + std::to_string(alpha));
    SdofBacklashOptions o = time_invariant();
    if (alpha > 0) o.stiffness = {{alpha, 0.0}};
    constexpr double kStep = 0.02;
    const auto sweep = sim::sdof_sweep(o, 0.6, 1.2, 31);
    const Jump up = largest_jump(sweep.up), down = largest_jump(sweep.down);
    ASSERT_GT(up.change, 0.0) << "run up must jump up";
    ASSERT_LT(down.change, 0.0) << "run down must jump down";
    const double omega_up = sweep.up[up.index].omega;        // last point before the jump
    const double omega_down = sweep.down[down.index].omega;  // last point before the jump
    // Softening: both jumps below the linear resonance, and the run down leaves the resonant
    // branch at a lower Omega than the run up reaches it: Omega_down < Omega_up means at least
    // two grid points where both responses coexist (measured: 0.72...0.82 for alpha_1 = 0,
    // 0.84...0.88 for alpha_1 = 0.2).
    EXPECT_LT(omega_up, 1.0);
    EXPECT_LT(omega_down, omega_up - kStep / 2);
    // Inside the hysteresis region the run-down (resonant) branch is several times the run-up
    // branch and has lost contact; the run-up branch has not.
    for (std::size_t i = 0; i < sweep.up.size(); ++i) {
      const SdofResponse& u = sweep.up[i];
      const SdofResponse& d = sweep.down[sweep.down.size() - 1 - i];
      ASSERT_DOUBLE_EQ(u.omega, d.omega);
      if (u.omega > omega_down - kStep / 2 && u.omega < omega_up + kStep / 2) {
        EXPECT_GT(d.rms, 2.0 * u.rms) << "Omega " << u.omega;
        EXPECT_TRUE(d.contact_lost) << "resonant branch at Omega " << u.omega;
        EXPECT_FALSE(u.contact_lost) << "non-resonant branch at Omega " << u.omega;
      }
    }
  }
}

TEST(SdofBacklash, LargeExcitationCausesBackFlankImpacts) {
  SdofBacklashOptions o = time_invariant();
  const SdofResponse single = sim::sdof_steady_state(o, 0.7, {1.1, 0.0});
  o.transmission_error = {{0.5, 0.0}};
  const SdofResponse both = sim::sdof_steady_state(o, 0.7, {1.1, 0.0});
  EXPECT_FALSE(single.back_impact);
  EXPECT_TRUE(both.contact_lost);
  EXPECT_TRUE(both.back_impact);
  EXPECT_LT(both.x_min, -o.half_backlash);
  EXPECT_GT(both.separated_fraction, 0.0);
}

// Kahraman & Singh 1991: with time-varying stiffness the mean load F_m alone excites the pair
// (alpha_1 F_m cos(Omega tau)), and k(tau) x also has a component at 2 Omega, which resonates at
// Omega = 1/2. Without parametric excitation the linear response rises monotonically there.
TEST(SdofBacklash, TimeVaryingStiffnessCreatesASuperHarmonicPeakNearHalfTheNaturalFrequency) {
  // A local maximum standing at least 15 % above the lowest response on either side of it
  // within 0.4...0.6 (measured: 1.47 over the left valley, 1.26 over the right one, where the
  // primary resonance's flank already rises).
  constexpr double kPeakContrast = 1.15;
  SdofBacklashOptions parametric;
  parametric.stiffness = {{0.2, 0.0}};
  parametric.transmission_error = {};
  const auto sweep = sim::sdof_sweep(parametric, 0.4, 0.6, 11);
  const auto by_rms = [](const SdofResponse& a, const SdofResponse& b) { return a.rms < b.rms; };
  const auto peak = std::max_element(sweep.up.begin(), sweep.up.end(), by_rms);
  EXPECT_GE(peak->omega, 0.46);
  EXPECT_LE(peak->omega, 0.54);
  ASSERT_NE(peak, sweep.up.begin());
  ASSERT_NE(peak + 1, sweep.up.end());
  const auto left_valley = std::min_element(sweep.up.begin(), peak, by_rms);
  const auto right_valley = std::min_element(peak + 1, sweep.up.end(), by_rms);
  EXPECT_GT(peak->rms, kPeakContrast * left_valley->rms);
  EXPECT_GT(peak->rms, kPeakContrast * right_valley->rms);

  const auto plain = sim::sdof_sweep(time_invariant(), 0.4, 0.6, 11);
  for (std::size_t i = 0; i + 1 < plain.up.size(); ++i) {
    EXPECT_GT(plain.up[i + 1].rms, plain.up[i].rms) << "Omega " << plain.up[i].omega;
  }
}

TEST(SdofBacklash, ContactLossResponseConvergesWithStepCount) {
  // On the contact-loss branch the kinks of f(x) limit RK4 locally to first order; quadrupling
  // the steps must still change the RMS by < 1e-4 relative (measured 4e-6 at 256 steps).
  constexpr double kRelTol = 1e-4;
  SdofBacklashOptions coarse;
  coarse.stiffness = {{0.2, 0.0}};
  coarse.transmission_error = {};
  SdofBacklashOptions fine = coarse;
  fine.steps_per_period = 1024;
  const sim::SdofState start{0.5, 0.0};  // starts apart, lands on the contact-loss branch
  const SdofResponse a = sim::sdof_steady_state(coarse, 0.95, start);
  const SdofResponse b = sim::sdof_steady_state(fine, 0.95, start);
  ASSERT_TRUE(a.contact_lost);
  EXPECT_NEAR(a.rms, b.rms, kRelTol * b.rms);
}

TEST(SdofBacklash, IsDeterministic) {
  const auto a = sim::sdof_sweep(time_invariant(), 0.7, 0.9, 3);
  const auto b = sim::sdof_sweep(time_invariant(), 0.7, 0.9, 3);
  for (std::size_t i = 0; i < a.down.size(); ++i) EXPECT_EQ(a.down[i].rms, b.down[i].rms);
}

TEST(SdofBacklash, BadOptionsThrowInputErrorNamingTheField) {
  const auto message = [](auto mutate) {
    SdofBacklashOptions o;
    mutate(o);
    return input_error_message([&] { sim::sdof_sweep(o, 0.5, 1.0, 3); });
  };
  EXPECT_NE(message([](SdofBacklashOptions& o) { o.damping_ratio = -0.1; }).find("damping_ratio"),
            std::string::npos);
  EXPECT_NE(message([](SdofBacklashOptions& o) { o.mean_load = -1.0; }).find("mean_load"),
            std::string::npos);
  EXPECT_NE(message([](SdofBacklashOptions& o) { o.half_backlash = -1.0; }).find("half_backlash"),
            std::string::npos);
  EXPECT_NE(message([](SdofBacklashOptions& o) {
              o.stiffness = {{0.7, 0}, {0.5, 0}};
            }).find("stiffness"),
            std::string::npos);
  EXPECT_NE(
      message([](SdofBacklashOptions& o) { o.steps_per_period = 8; }).find("steps_per_period"),
      std::string::npos);
  EXPECT_NE(message([](SdofBacklashOptions& o) { o.record_periods = 0; }).find("record_periods"),
            std::string::npos);
  EXPECT_NE(input_error_message([] {
              sim::sdof_sweep(SdofBacklashOptions{}, 1.0, 0.5, 3);
            }).find("omega_max"),
            std::string::npos);
  EXPECT_NE(input_error_message([] {
              sim::sdof_sweep(SdofBacklashOptions{}, 0.5, 1.0, 1);
            }).find("points"),
            std::string::npos);
}

}  // namespace
