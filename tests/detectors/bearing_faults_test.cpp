#include "detect/bearing/bearing_faults.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "detect/gear/fault_bands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/bearing_rates.hpp"

namespace {

using detect::BearingDecisionStatus;
using detect::BearingFault;

constexpr double kRoundOff = 1e-12;

diag::BearingSpec cwru_6205() { return diag::skf6205("SKF 6205-2RS JEM (CWRU drive end)"); }

// ---- Fault frequencies
// ------------------------------------------------------------------------------

// The Case Western Reserve University bearing data centre's table for the 6205-2RS JEM (multiples
// of the shaft speed): BPFI 5.4152, BPFO 3.5848, FTF 0.39828, BSF 4.7135. The table's "BSF" is the
// ball-fault rate 2 BSF (bearing_faults.hpp). Its values are rounded to 4 decimals:
// kPublishedRounding = 5e-5. Its FTF (5 decimals) disagrees with its own BPFO / 9 = 0.398311 by
// 3e-5, more than its rounding: geometry gives 0.398309 = BPFO / n; we check the published FTF to
// kFtfTable = 4e-5 and the identity FTF = BPFO / n to round-off.
TEST(BearingFrequencies, ReproduceTheCwruTableFor6205) {
  const double fr = 1797.0 / 60.0;
  const detect::BearingFrequencies f = detect::bearing_frequencies(cwru_6205(), fr);
  constexpr double kPublishedRounding = 5e-5;
  constexpr double kFtfTable = 4e-5;
  EXPECT_NEAR(f.bpfi_hz / fr, 5.4152, kPublishedRounding);
  EXPECT_NEAR(f.bpfo_hz / fr, 3.5848, kPublishedRounding);
  EXPECT_NEAR(f.ball_fault_hz / fr, 4.7135, kPublishedRounding);
  EXPECT_NEAR(f.ftf_hz / fr, 0.39828, kFtfTable);
  EXPECT_NEAR(f.ftf_hz, f.bpfo_hz / 9.0, kRoundOff);
  EXPECT_NEAR(f.bsf_hz * 2.0, f.ball_fault_hz, kRoundOff);
  EXPECT_DOUBLE_EQ(f.shaft_hz, fr);
}

// Hand-computed: n = 8, P_d = 40 mm, B_d = 8 mm, phi = 60 deg -> rho = 0.2 cos 60 = 0.1;
// FTF = 0.45, BPFO = 3.6, BPFI = 4.4, BSF = (40/16)(1 - 0.01) = 2.475, ball fault 4.95 (x f_r).
// Kinematic identities: BPFO + BPFI = n f_r, and every line scales with f_r.
TEST(BearingFrequencies, MatchHandComputedAngularContactBearing) {
  diag::BearingSpec b;
  b.rolling_elements = 8;
  b.pitch_diameter_m = 0.040;
  b.element_diameter_m = 0.008;
  b.contact_angle_rad = std::numbers::pi / 3;
  for (double fr : {1.0, 25.0, 173.3}) {
    const auto f = detect::bearing_frequencies(b, fr);
    EXPECT_NEAR(f.ftf_hz, 0.45 * fr, kRoundOff * fr);
    EXPECT_NEAR(f.bpfo_hz, 3.6 * fr, kRoundOff * fr);
    EXPECT_NEAR(f.bpfi_hz, 4.4 * fr, kRoundOff * fr);
    EXPECT_NEAR(f.bsf_hz, 2.475 * fr, kRoundOff * fr);
    EXPECT_NEAR(f.ball_fault_hz, 4.95 * fr, kRoundOff * fr);
    EXPECT_NEAR(f.bpfo_hz + f.bpfi_hz, 8 * fr, kRoundOff * fr);
  }
}

TEST(BearingFrequencies, RejectImpossibleGeometryNamingTheField) {
  auto expect_field = [](diag::BearingSpec b, double fr, const std::string& field) {
    try {
      detect::bearing_frequencies(b, fr);
      ADD_FAILURE() << "expected InputError for " << field;
    } catch (const diag::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  auto b = cwru_6205();
  b.rolling_elements = 2;
  expect_field(b, 30, "rolling_elements");
  b = cwru_6205();
  b.element_diameter_m = b.pitch_diameter_m;
  expect_field(b, 30, "element_diameter_m");
  b = cwru_6205();
  b.contact_angle_rad = std::numbers::pi / 2;
  expect_field(b, 30, "contact_angle_rad");
  expect_field(cwru_6205(), 0.0, "shaft_hz");
}

// ---- Bands
// ---------------------------------------------------------------------------------------------

TEST(FaultBands, PlaceHarmonicsAndSidebandsWithTheGivenWidth) {
  const auto f = detect::bearing_frequencies(cwru_6205(), 30.0);
  detect::FaultBandOptions opt;
  opt.harmonics = 2;
  opt.sidebands = 1;
  opt.width_hz = 2.0;
  const auto bands = detect::bearing_fault_bands(f, opt);
  // FTF and BPFO carry no sidebands (2 bands each); BPFI (+- f_r) and BALL (+- FTF): 2 x 3 each.
  ASSERT_EQ(bands.size(), 16u);
  int bpfi = 0;
  for (const auto& b : bands) {
    EXPECT_NEAR(b.high_hz - b.low_hz, 2.0, kRoundOff);
    if (b.family != 2) continue;
    ++bpfi;
    EXPECT_NEAR(b.centre_hz, b.harmonic * f.bpfi_hz + b.sideband * 30.0, kRoundOff);
    if (b.harmonic == 2 && b.sideband == -1) {
      EXPECT_EQ(b.label, "2xBPFI-1xSB");
    }
  }
  EXPECT_EQ(bpfi, 6);
}

TEST(FaultBands, DropSidebandsBelowDcAndDefaultToTenPercentWidth) {
  const std::vector<detect::FaultFrequency> fam = {{"X", 5.0, 10.0}};
  detect::FaultBandOptions opt;
  opt.harmonics = 1;
  opt.sidebands = 1;
  const auto bands = detect::fault_bands(fam, opt);
  ASSERT_EQ(bands.size(), 2u);  // 5 and 15; -5 is dropped
  EXPECT_NEAR(bands[0].centre_hz, 5.0, kRoundOff);
  EXPECT_NEAR(bands[0].high_hz - bands[0].low_hz, 0.5, kRoundOff);
  EXPECT_NEAR(bands[1].centre_hz, 15.0, kRoundOff);
  opt.harmonics = 0;
  EXPECT_THROW(detect::fault_bands(fam, opt), diag::InputError);
}

// Hand-computed metrics on a 10-bin amplitude spectrum a = {0,1,0,3,2,0,0,5,0,1} at f = 0..9 Hz:
//   band [2.5, 4.5]: bins 3, 4 -> peak 3 at 3 Hz, energy 9 + 4 = 13;
//   band [6.5, 7.5]: bin 7 -> peak 5 at 7 Hz, energy 25;  band [9.5, 12]: no bin.
//   total energy sum a^2 = 1 + 9 + 4 + 25 + 1 = 40; total band energy 38.
// As powers per bin the same bands hold 3 + 2 = 5 and 5, total 12.
TEST(FaultBandMetrics, MatchHandComputedPeaksAndEnergies) {
  const std::vector<double> f = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const std::vector<double> a = {0, 1, 0, 3, 2, 0, 0, 5, 0, 1};
  std::vector<detect::FaultBand> bands(3);
  bands[0].low_hz = 2.5, bands[0].high_hz = 4.5;
  bands[1].low_hz = 6.5, bands[1].high_hz = 7.5;
  bands[2].low_hz = 9.5, bands[2].high_hz = 12;
  const auto m = detect::fault_band_metrics({f, a}, bands);
  EXPECT_DOUBLE_EQ(m.total_energy, 40.0);
  EXPECT_DOUBLE_EQ(m.total_band_energy, 38.0);
  EXPECT_DOUBLE_EQ(m.bands[0].peak_value, 3.0);
  EXPECT_DOUBLE_EQ(m.bands[0].peak_frequency_hz, 3.0);
  EXPECT_DOUBLE_EQ(m.bands[0].energy, 13.0);
  EXPECT_DOUBLE_EQ(m.bands[0].energy_fraction, 13.0 / 40.0);
  EXPECT_EQ(m.bands[0].bins, 2);
  EXPECT_DOUBLE_EQ(m.bands[1].energy, 25.0);
  EXPECT_DOUBLE_EQ(m.bands[1].peak_frequency_hz, 7.0);
  EXPECT_EQ(m.bands[2].bins, 0);
  EXPECT_TRUE(std::isnan(m.bands[2].peak_frequency_hz));
  const auto p = detect::fault_band_metrics({f, a}, bands, detect::SpectrumScale::kPower);
  EXPECT_DOUBLE_EQ(p.bands[0].energy, 5.0);
  EXPECT_DOUBLE_EQ(p.total_energy, 12.0);
  // A flat PSD of 1 on the uneven grid {0, 1, 3, 4}: bin widths 1, 1.5, 1.5, 1 -> total 5.
  const std::vector<double> fu = {0, 1, 3, 4}, ones = {1, 1, 1, 1};
  EXPECT_DOUBLE_EQ(
      detect::fault_band_metrics({fu, ones}, {}, detect::SpectrumScale::kPowerDensity).total_energy,
      5.0);
  const std::vector<double> bad_f = {0, 2, 1};
  const std::vector<double> three = {1, 1, 1};
  EXPECT_THROW(detect::fault_band_metrics({bad_f, three}, bands), diag::InputError);
}

// measure_line: a line of 8 over a floor of ones reads 20 log10(8) = 18.06 dB; the floor's median
// ignores the line itself and another strong line in the floor window.
TEST(MeasureLine, ReadsProminenceOverTheMedianFloor) {
  std::vector<double> f(101), a(101, 1.0);
  for (int k = 0; k <= 100; ++k) f[k] = 0.5 * k;
  a[40] = 8.0;   // 20 Hz
  a[46] = 50.0;  // 23 Hz: in the floor window, must not move the median
  const auto m = detect::measure_line({f, a}, 20.3, 1.0, 6.0);
  ASSERT_TRUE(m.valid);
  EXPECT_DOUBLE_EQ(m.frequency_hz, 20.0);
  EXPECT_DOUBLE_EQ(m.floor, 1.0);
  EXPECT_NEAR(m.prominence_db, 20 * std::log10(8.0), kRoundOff);
  EXPECT_FALSE(detect::measure_line({f, a}, 49.8, 1.0, 6.0).valid);  // window leaves the spectrum
}

// ---- Bearing decision
// ------------------------------------------------------------------------------

// A synthetic envelope amplitude spectrum, 0..1000 Hz at 0.5 Hz: Rayleigh noise (the magnitude of
// a complex Gaussian bin, scale sigma = 1, median 1.18) plus, for each comb, lines at h f0 (1 +
// slip) h = 1..3 of amplitude level / h over the noise median (an envelope comb decays with the
// harmonic), each with +- f_r sidebands at a third of its height when sideband_hz > 0.
struct Comb {
  double f0_hz;
  double level;        // first harmonic over the noise median (linear)
  double sideband_hz;  // 0: none
};
std::vector<double> envelope_spectrum(const std::vector<double>& f, std::uint64_t seed,
                                      const std::vector<Comb>& combs, double slip = 0.005) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> a(f.size());
  for (double& v : a) {
    const double re = g(rng), im = g(rng);
    v = std::hypot(re, im);
  }
  const double median = std::sqrt(2 * std::log(2.0));
  const double df = f[1] - f[0];
  auto add = [&](double hz, double amp) {
    const auto k = static_cast<std::size_t>(std::lround(hz / df));
    if (k < a.size()) a[k] += amp;
  };
  for (const Comb& c : combs) {
    for (int h = 1; h <= 3; ++h) {
      const double centre = h * c.f0_hz * (1 + slip);
      add(centre, c.level * median / h);
      if (c.sideband_hz > 0) {
        add(centre - c.sideband_hz, c.level * median / (3 * h));
        add(centre + c.sideband_hz, c.level * median / (3 * h));
      }
    }
  }
  return a;
}

std::vector<double> grid() {
  std::vector<double> f(2001);
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = 0.5 * static_cast<double>(k);
  return f;
}

detect::BearingFrequencies cwru_at_1797_rpm() {
  return detect::bearing_frequencies(cwru_6205(), 1797.0 / 60.0);
}

// A BPFO comb 20 dB over the noise median (slipping 0.5 %) is named outer race, on every seed.
TEST(DiagnoseBearing, NamesAnOuterRaceComb) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto a = envelope_spectrum(f, seed, {{bf.bpfo_hz, 10.0, 0.0}});
    const auto d = detect::diagnose_bearing_from_envelope({f, a}, bf);
    EXPECT_EQ(d.status, BearingDecisionStatus::kFault) << "seed " << seed;
    EXPECT_EQ(d.fault, BearingFault::kOuterRace) << "seed " << seed;
  }
}

// Inner race (with its shaft-rate sidebands) and ball (at 2 BSF, with the cage-rate sidebands a
// ball's passage through the load zone gives) combs are named as such.
TEST(DiagnoseBearing, NamesInnerRaceAndBallCombs) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  const auto inner = detect::diagnose_bearing_from_envelope(
      {f, envelope_spectrum(f, 3, {{bf.bpfi_hz, 10.0, bf.shaft_hz}})}, bf);
  EXPECT_EQ(inner.fault, BearingFault::kInnerRace);
  // Sidebands at a third of the carrier: 30 x median / 3 = 20 dB over the floor.
  const auto ball = detect::diagnose_bearing_from_envelope(
      {f, envelope_spectrum(f, 4, {{bf.ball_fault_hz, 30.0, bf.ftf_hz}})}, bf);
  EXPECT_EQ(ball.fault, BearingFault::kRollingElement);
  EXPECT_GE(ball.families[3].sidebands_detected, 2);
}

// The 2 BSF lines without any cage-rate modulation (no FTF sideband, no FTF line) are not a ball
// fault's signature: nothing is named, and the decision says why.
TEST(DiagnoseBearing, CallsBallLinesWithoutCageModulationAmbiguous) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  const auto d = detect::diagnose_bearing_from_envelope(
      {f, envelope_spectrum(f, 4, {{bf.ball_fault_hz, 10.0, 0.0}})}, bf);
  EXPECT_EQ(d.status, BearingDecisionStatus::kAmbiguous);
  EXPECT_EQ(d.fault, BearingFault::kNone);
  EXPECT_TRUE(d.unmodulated_ball);
  EXPECT_TRUE(d.candidates.empty());
}

// FTF lines alone are at most a cage note, never a finding (a ball fault modulates at FTF; a cage
// has no impact family of its own to confirm it).
TEST(DiagnoseBearing, GivesACageNoteNotAFindingForFtfLinesAlone) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto d = detect::diagnose_bearing_from_envelope(
        {f, envelope_spectrum(f, seed, {{bf.ftf_hz, 10.0, 0.0}})}, bf);
    EXPECT_EQ(d.status, BearingDecisionStatus::kNoFault) << "seed " << seed;
    EXPECT_EQ(d.fault, BearingFault::kNone);
    EXPECT_TRUE(d.cage_note) << "seed " << seed;
    EXPECT_TRUE(d.families[0].lines_pass);
    EXPECT_FALSE(d.families[0].passes);
  }
}

// A ball fault's strong cage modulation also puts lines in the BPFI windows (m BSF + k FTF for
// large k); the inner-race family then passes without a single shaft sideband while the ball
// family carries its FTF sidebands and FTF lines: the ball explains the inner-race lines.
TEST(DiagnoseBearing, BallModulationExplainsCoincidentInnerRaceLines) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  const auto a = envelope_spectrum(
      f, 12,
      {{bf.ball_fault_hz, 30.0, bf.ftf_hz}, {bf.bpfi_hz, 12.0, 0.0}, {bf.ftf_hz, 10.0, 0.0}});
  const auto d = detect::diagnose_bearing_from_envelope({f, a}, bf);
  EXPECT_EQ(d.fault, BearingFault::kRollingElement);
  EXPECT_TRUE(d.families[2].passes);
  EXPECT_TRUE(d.families[2].explained);
  // With shaft sidebands of its own the inner-race family is not explained away: a tie, nothing.
  const auto b = envelope_spectrum(f, 12,
                                   {{bf.ball_fault_hz, 30.0, bf.ftf_hz},
                                    {bf.bpfi_hz, 30.0, bf.shaft_hz},
                                    {bf.ftf_hz, 10.0, 0.0}});
  EXPECT_EQ(detect::diagnose_bearing_from_envelope({f, b}, bf).status,
            BearingDecisionStatus::kAmbiguous);
}

// Comb support: 8 harmonics of BPFO at 2 x the noise median (6 dB, under every line threshold)
// stand above the 39 detuned combs on most seeds; noise alone does so with probability
// 1 / 40 = 2.5 % by construction (rank test), so on 100 seeds at most a handful: 8 allows for the
// binomial spread (mean 2.5, P(> 8) ~ 1e-3) and fails a test that has lost its null.
TEST(CombSupport, FindsAWeakFamilyAndRarelyNoise) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  const double median = std::sqrt(2 * std::log(2.0));
  const double df = f[1] - f[0];
  int found = 0, noise = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    auto a = envelope_spectrum(f, 500 + seed, {});
    EXPECT_TRUE(detect::comb_support({f, a}, bf.bpfo_hz).harmonics >= 2);
    if (detect::comb_support({f, a}, bf.bpfo_hz).supported) ++noise;
    for (int h = 1; h <= 8; ++h)
      a[static_cast<std::size_t>(std::lround(h * bf.bpfo_hz / df))] += 2.0 * median;
    if (detect::comb_support({f, a}, bf.bpfo_hz).supported) ++found;
  }
  EXPECT_LE(noise, 8);
  EXPECT_GE(found, 80);
}

// Noise alone: nothing is named on any of 200 seeds. The thresholds' rationale (fault_bands.hpp)
// predicts about 1e-3 false alarms per spectrum here (search windows of 5..20 bins, four
// families), i.e. ~0.2 expected over 200 seeds; a detector with a threshold a few dB lower would
// fail this test (at 6 dB a single noise bin passes with probability 0.06, not 0.001).
TEST(DiagnoseBearing, NamesNothingOnNoiseAlone) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  int alarms = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const auto d =
        detect::diagnose_bearing_from_envelope({f, envelope_spectrum(f, 1000 + seed, {})}, bf);
    if (d.status != BearingDecisionStatus::kNoFault) ++alarms;
    EXPECT_EQ(d.fault, BearingFault::kNone);
  }
  EXPECT_EQ(alarms, 0);
}

// Two families of equal strength: neither clearly beats the other, so no fault is named; the
// result says kAmbiguous and lists both as candidates.
TEST(DiagnoseBearing, CallsTwoEqualFamiliesAmbiguous) {
  const auto f = grid();
  const auto bf = cwru_at_1797_rpm();
  const auto a = envelope_spectrum(f, 11, {{bf.bpfo_hz, 10.0, 0.0}, {bf.bpfi_hz, 10.0, 0.0}});
  const auto d = detect::diagnose_bearing_from_envelope({f, a}, bf);
  EXPECT_EQ(d.status, BearingDecisionStatus::kAmbiguous);
  EXPECT_EQ(d.fault, BearingFault::kNone);
  ASSERT_EQ(d.candidates.size(), 2u);
  EXPECT_EQ(d.candidates[0], BearingFault::kOuterRace);
  EXPECT_EQ(d.candidates[1], BearingFault::kInnerRace);
  // The same two families with one 12 dB weaker: the stronger is named.
  const auto b = envelope_spectrum(f, 11, {{bf.bpfo_hz, 16.0, 0.0}, {bf.bpfi_hz, 4.0, 0.0}});
  EXPECT_EQ(detect::diagnose_bearing_from_envelope({f, b}, bf).fault, BearingFault::kOuterRace);
}

}  // namespace
