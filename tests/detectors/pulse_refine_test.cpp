#include "detect/angular/pulse_refine.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace {

using std::numbers::pi;

constexpr double kFs = 10000.0;    // [Hz]
constexpr double kInputHz = 25.3;  // [Hz]
constexpr double kDurationS = 2.2;

diag::Gearbox gearbox() {
  return diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
}

// True input pulses k / f; as a 0/1 tacho sampled at fs would give them: late by a uniform
// [0, 1/fs).
std::vector<double> quantised_pulses(double rate_error) {
  std::vector<double> p;
  for (int k = 0; k / kInputHz < kDurationS; ++k) {
    const double t = k / (kInputHz * (1.0 + rate_error));
    p.push_back(std::ceil(t * kFs) / kFs);
  }
  return p;
}

TEST(PulseRefine, TheFitAveragesTheQuantisationOfTheEdges) {
  const std::vector<double> p = quantised_pulses(0.0);
  const std::vector<double> s = detect::smooth_pulse_times_polynomial(p, 3);
  ASSERT_EQ(s.size(), p.size());
  // Each detected pulse is off by up to 1/fs (100 us); the fit of 56 pulses by about
  // 0.3 / fs / sqrt(56) around the mean delay 0.5 / fs; tolerance: 0.5 / fs + 0.2 / fs.
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_NEAR(s[k], k / kInputHz, 0.7 / kFs) << k;
  }
  EXPECT_EQ(detect::smooth_pulse_times_polynomial(p, 0), p);  // degree 0: as detected
}

// A loud input mesh line (order 18) and a tacho whose rate is off by 3e-5: the phase of the
// line moves by 2 pi 18 x 3e-5 per revolution; the refinement follows it on the fastest shaft
// (the input) and moves the pulses onto the shaft's true revolutions.
TEST(PulseRefine, ARateErrorIsCorrectedFromTheMeshLinePhase) {
  const diag::Gearbox gb = gearbox();
  const std::size_t n = static_cast<std::size_t>(kDurationS * kFs);
  diag::Recording rec;
  diag::Signal s;
  s.name = "input_bearing1_along_loa";
  s.location = "input_bearing1";
  s.direction = diag::Direction::kAlongLoa;
  s.fs_hz = kFs;
  s.unit = "m/s^2";
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i / kFs;
    s.samples.push_back(300.0 * std::cos(2 * pi * 18 * kInputHz * t + 0.3) + noise(rng));
  }
  rec.signals.push_back(s);
  constexpr double kRateError = 3e-5;
  const std::vector<double> p = quantised_pulses(kRateError);
  const detect::RefinedPulses r = detect::refine_pulses(rec, gb, "input", p);
  EXPECT_EQ(r.shaft, "input");
  EXPECT_GT(r.line, 0u);
  EXPECT_EQ(r.channel, s.name);
  EXPECT_FALSE(r.note.empty());
  // The uncorrected end pulses are off by ~ 3e-5 x 2.2 s / 2 = 33 us plus the quantisation;
  // corrected, within the phase noise of the line (1/300 rad at order 18: 0.1 us) and the
  // interpolation between revolution middles; tolerance 20 us, against 33 us uncorrected.
  const detect::RefinedPulses plain = [&] {
    detect::PulseRefineOptions o;
    o.phase_correction = false;
    return detect::refine_pulses(rec, gb, "input", p, o);
  }();
  double worst_plain = 0.0, worst = 0.0;
  for (std::size_t k = 2; k + 2 < r.pulses.size(); ++k) {
    worst_plain = std::max(worst_plain, std::abs(plain.pulses[k] - k / kInputHz));
    worst = std::max(worst, std::abs(r.pulses[k] - k / kInputHz));
  }
  EXPECT_GT(worst_plain, 25e-6) << "the error this test is about is absent";
  EXPECT_LT(worst, 20e-6);
}

TEST(PulseRefine, BadInputsAreRefused) {
  const diag::Gearbox gb = gearbox();
  const diag::Recording rec;
  const std::vector<double> p = quantised_pulses(0.0);
  EXPECT_THROW(detect::refine_pulses(rec, gb, "no_such_shaft", p), diag::InputError);
  EXPECT_THROW(detect::refine_pulses(rec, gb, "input", std::vector<double>{0.0, 0.1}),
               diag::InputError);
  EXPECT_THROW(detect::refine_pulses(rec, gb, "input", std::vector<double>{0.0, 0.2, 0.1}),
               diag::InputError);
  EXPECT_THROW(detect::smooth_pulse_times_polynomial(p, 9), diag::InputError);
  detect::PulseRefineOptions o;
  o.band_fraction = 0.0;
  EXPECT_THROW(detect::refine_pulses(rec, gb, "input", p, o), diag::InputError);
}

}  // namespace
