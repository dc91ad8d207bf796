// diagnose_bearings_from_signal on synthetic signals: a ringing outer-race impact train under shaft
// lines and noise (the closed-form case), noise alone, and bad input.
#include "detect/bearing/bearing_diagnosis.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <vector>

#include "diag/error.hpp"
#include "diag/gearbox/bearing_rates.hpp"

namespace {

constexpr double kFsHz = 12000.0;
constexpr double kShaftHz = 25.0;
constexpr std::size_t kSamples = 1 << 16;  // 5.5 s: 0.18 Hz envelope-spectrum bins

diag::BearingSpec skf6205() { return diag::skf6205("de"); }

diag::Signal noise_and_shaft_lines(unsigned seed) {
  diag::Signal s;
  s.name = "acc";
  s.fs_hz = kFsHz;
  s.samples.resize(kSamples);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  for (std::size_t j = 0; j < kSamples; ++j) {
    const double t = static_cast<double>(j) / kFsHz;
    // Shaft harmonics 10x stronger than the noise: what prewhitening and the band guard face.
    double v = g(rng);
    for (int h = 1; h <= 5; ++h) v += 10.0 / h * std::sin(2 * std::numbers::pi * h * kShaftHz * t);
    s.samples[j] = v;
  }
  return s;
}

// One impact per BPFO period (with 0.5 % random period jitter, as rolling elements slip), each
// ringing a 3.3 kHz resonance with 5 % damping, peak 3 noise sigmas.
void add_outer_race_impacts(diag::Signal& s, double bpfo_hz, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> jitter(0.0, 0.005);
  const double wn = 2 * std::numbers::pi * 3300.0, zeta = 0.05;
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  for (double t0 = 0.01; t0 < s.duration_s() - 0.01; t0 += (1 + jitter(rng)) / bpfo_hz) {
    const auto j0 = static_cast<std::size_t>(std::ceil(t0 * kFsHz));
    for (std::size_t j = j0; j < std::min(s.samples.size(), j0 + 240); ++j) {
      const double t = static_cast<double>(j) / kFsHz - t0;
      s.samples[j] += 3.0 * std::exp(-zeta * wn * t) * std::sin(wd * t);
    }
  }
}

}  // namespace

TEST(BearingDiagnosis, OuterRaceImpactTrainUnderShaftLinesIsOuterRace) {
  const diag::BearingSpec b = skf6205();
  const auto f = detect::bearing_frequencies(b, kShaftHz);
  diag::Signal s = noise_and_shaft_lines(1);
  add_outer_race_impacts(s, f.bpfo_hz, 2);
  const auto d = detect::diagnose_bearings_from_signal(s, kShaftHz, std::span(&b, 1));
  ASSERT_EQ(d.findings.size(), 1u) << detect::to_json(d).dump(1);
  EXPECT_EQ(diag::to_string(d.findings[0].fault), "outer_race");
  EXPECT_EQ(d.findings[0].bearing, "de");
  EXPECT_EQ(d.findings[0].channel, "acc");
  EXPECT_DOUBLE_EQ(d.findings[0].frequency_hz, f.bpfo_hz);
  // The kurtogram band must hold the resonance that the impacts ring.
  EXPECT_LE(d.band_centre_hz - 0.5 * d.band_width_hz, 3300.0);
  EXPECT_GE(d.band_centre_hz + 0.5 * d.band_width_hz, 3300.0);
  const auto j = detect::to_json(d);
  EXPECT_EQ(j["findings"][0]["fault"], "outer_race");
  EXPECT_EQ(j["bearings"][0]["status"], "fault");
}

TEST(BearingDiagnosis, NoiseAndShaftLinesAloneGiveNoFinding) {
  const diag::BearingSpec b = skf6205();
  for (unsigned seed : {3u, 4u, 5u}) {
    const auto d = detect::diagnose_bearings_from_signal(noise_and_shaft_lines(seed), kShaftHz,
                                                         std::span(&b, 1));
    EXPECT_TRUE(d.findings.empty()) << detect::to_json(d).dump(1);
  }
}

TEST(BearingDiagnosis, RejectsBadInputNamingTheField) {
  const diag::BearingSpec b = skf6205();
  const diag::Signal s = noise_and_shaft_lines(1);
  EXPECT_THROW(detect::diagnose_bearings_from_signal(s, 0.0, std::span(&b, 1)), diag::InputError);
  EXPECT_THROW(detect::diagnose_bearings_from_signal(s, kShaftHz, {}), diag::InputError);
  detect::BearingDiagnosisOptions opt;
  opt.min_band_low_factor = -1;
  EXPECT_THROW(detect::diagnose_bearings_from_signal(s, kShaftHz, std::span(&b, 1), opt),
               diag::InputError);
  // At 1 kHz no band can be 3 BPFI wide above BPFI: the rate is too low, said so.
  diag::Signal slow = s;
  slow.fs_hz = 1000.0;
  try {
    detect::diagnose_bearings_from_signal(slow, kShaftHz, std::span(&b, 1));
    FAIL() << "no throw";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too low"), std::string::npos) << e.what();
  }
}
