#include "detect/gear/gear_damage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace {

using std::numbers::pi;

// Synthetic two-stage gearbox recording (testdata/gearbox/three_shaft.json: input z1 = 18 ->
// counter z2 = 36, counter z3 = 18 -> output z4 = 36; f_counter = f_in / 2, f_out = f_in / 4).
// Every bearing channel holds the two mesh tones (3 harmonics each), Gaussian noise and,
// optionally, a local amplification of one mesh tone once per revolution of one shaft: the
// signature of a localised tooth fault. The input tacho is a 0/1 train sampled at fs, so its
// edges are uncertain by half a sample, as the simulator's.
constexpr double kFs = 10000.0;     // [Hz]
constexpr double kInputHz = 25.3;   // not a divisor of fs: the sample grid does not lock on
constexpr double kDurationS = 2.2;  // 13.9 output revolutions, >= min_revolutions + margins
constexpr double kNoiseRms = 1.0;   // [m/s^2]
constexpr double kMeshAmp = 5.0;    // [m/s^2]
constexpr double kBurstAmp = 12.0;  // [m/s^2]: in a 55-revolution counter TSA the noise is
                                    // 1/sqrt(55) = 0.13, so the burst is 90x the noise there

diag::Gearbox gearbox() {
  return diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
}

// tacho_rate: the tacho turns at tacho_rate x the shaft speed the vibration follows (a speed
// estimate off by tacho_rate - 1).
// tooth_amps: when not empty, one transient per tooth of the counter's 36-tooth gear z2 per
// counter revolution, tooth t with amplitude tooth_amps[t] [m/s^2] (a short burst of the first
// mesh.s carrier, sigma 0.25 of a tooth period): pitch errors (every tooth) and a local fault
// (one tooth) as the difference signal sees them.
diag::Recording synthetic(const std::string& fault_shaft, std::uint64_t seed,
                          double noise_rms = kNoiseRms, double mesh_amp = kMeshAmp,
                          double tacho_rate = 1.0, double input_hz = kInputHz,
                          const std::vector<double>& tooth_amps = {}) {
  const std::size_t n = static_cast<std::size_t>(kDurationS * kFs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_rms);
  const double f_mesh1 = 18 * input_hz, f_mesh2 = 18 * input_hz / 2;
  double f_fault = 0;
  if (fault_shaft == "input") f_fault = input_hz;
  if (fault_shaft == "counter") f_fault = input_hz / 2;
  if (fault_shaft == "output") f_fault = input_hz / 4;
  diag::Recording rec;
  for (const std::string shaft : {"input", "counter", "output"}) {
    diag::Signal s;
    s.name = shaft + "_bearing1_along_loa";
    s.location = shaft + "_bearing1";
    s.direction = diag::Direction::kAlongLoa;
    s.fs_hz = kFs;
    s.unit = "m/s^2";
    s.samples.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = i / kFs;
      double x = noise(rng);
      for (int h = 1; h <= 3; ++h) {
        x += mesh_amp / h * std::cos(2 * pi * h * f_mesh1 * t + 0.3 * h);
        x += mesh_amp / h * std::cos(2 * pi * h * f_mesh2 * t + 0.7 * h);
      }
      if (f_fault > 0) {
        // Once per revolution of the faulty shaft, 0.3 revolutions after its start, the mesh
        // tone of that shaft's mesh is locally amplified (a Gaussian envelope, sigma 2 ms, about
        // one tooth period): McFadden's amplitude-modulation model of a localised tooth fault.
        const double period = 1.0 / f_fault;
        const double tc = (std::floor(t / period - 0.3 + 0.5) + 0.3) * period;
        const double u = (t - tc) / 2e-3;
        const double f_carrier = fault_shaft == "input" ? f_mesh1 : f_mesh2;
        x += kBurstAmp * std::exp(-0.5 * u * u) * std::cos(2 * pi * f_carrier * t);
      }
      if (!tooth_amps.empty()) {
        const double tooth_period = 1.0 / f_mesh1;  // z2's teeth pass at the first mesh
        const double k = std::floor(t / tooth_period + 0.5);
        const double u = (t - k * tooth_period) / (0.25 * tooth_period);
        const auto tooth = static_cast<std::size_t>(static_cast<long long>(k) % 36);
        x += tooth_amps[tooth] * std::exp(-0.5 * u * u) *
             std::cos(2 * pi * 111.0 * (input_hz / 2) * t);
      }
      s.samples[i] = x;
    }
    rec.signals.push_back(std::move(s));
  }
  diag::Signal tacho;
  tacho.name = "input";
  tacho.location = "input";
  tacho.direction = diag::Direction::kTacho;
  tacho.fs_hz = kFs;
  tacho.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double revs = tacho_rate * input_hz * i / kFs;
    tacho.samples[i] = revs - std::floor(revs) < 0.1 ? 1.0 : 0.0;
  }
  rec.tachos.push_back(std::move(tacho));
  return rec;
}

const detect::ShaftDamage& shaft(const detect::GearDamageResult& r, const std::string& name) {
  for (const auto& s : r.shafts) {
    if (s.shaft == name) return s;
  }
  throw std::runtime_error("no shaft " + name);
}

class GearDamageOnShaft : public ::testing::TestWithParam<std::string> {};

TEST_P(GearDamageOnShaft, BurstOncePerRevolutionIsFoundOnItsShaft) {
  const diag::Gearbox gb = gearbox();
  const std::string truth = GetParam();
  const auto r = detect::locate_gear_damage(synthetic(truth, 7), gb);
  ASSERT_EQ(r.status, "damaged") << nlohmann::json(detect::to_json(r)).dump(1);
  ASSERT_EQ(r.findings.size(), 1u);
  EXPECT_EQ(r.findings[0].shaft, truth);
  EXPECT_EQ(r.findings[0].gears, (truth == "input"     ? std::vector<std::string>{"z1"}
                                  : truth == "counter" ? std::vector<std::string>{"z2", "z3"}
                                                       : std::vector<std::string>{"z4"}));
  EXPECT_GT(r.findings[0].confidence, 0.0);
  // Shafts slower than the faulty one are blind to it: their exclusive orders hold only noise,
  // so their SNR stays below the significance threshold (noise alone: 1 +- 0.1, see
  // MeshTonesAndNoiseAloneAreHealthy).
  const double min_snr = detect::GearDamageOptions{}.min_snr;
  if (truth != "output") {
    EXPECT_LT(shaft(r, "output").snr, min_snr);
  }
  if (truth == "input") {
    EXPECT_LT(shaft(r, "counter").snr, min_snr);
  }
}

INSTANTIATE_TEST_SUITE_P(EachShaft, GearDamageOnShaft,
                         ::testing::Values("input", "counter", "output"));

TEST(GearDamage, MeshTonesAndNoiseAloneAreHealthy) {
  const diag::Gearbox gb = gearbox();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto r = detect::locate_gear_damage(synthetic("", seed), gb);
    EXPECT_EQ(r.status, "healthy") << nlohmann::json(detect::to_json(r)).dump(1);
    EXPECT_TRUE(r.findings.empty());
    for (const auto& s : r.shafts) {
      // The mesh tones are removed; what is left in the exclusive orders is Gaussian noise, and
      // its energy over the noise energy estimated from the revolution-to-revolution scatter is
      // a ratio of two chi-squares: 1 with a standard deviation of about
      // sqrt(1/M + 1/(M (N - 1))), M the orders kept. The output shaft (6.3 Hz, 10 kHz) keeps
      // the odd orders up to 0.8 x 5000 / 6.3 = 632 less the mesh sidebands, M ~ 300; N = 13:
      // sigma ~ 0.06. The input keeps ~150 orders with N = 54: 0.08. Tolerance 5 sigma of the
      // worse: 0.4; FM4 of noise alone is 3 +- sqrt(24 / (2 M)) = 0.3, 5 sigma 1.5.
      constexpr double kSnrTol = 0.4;
      constexpr double kFm4Tol = 1.5;
      EXPECT_NEAR(s.snr, 1.0, kSnrTol) << s.shaft;
      EXPECT_NEAR(s.fm4, 3.0, kFm4Tol) << s.shaft;
      EXPECT_EQ(s.score, 1.0) << s.shaft << ": not significant, so not scored";
      EXPECT_GT(s.revolutions, 8) << s.shaft;
    }
  }
}

// Noise only dilutes the tooth score (it adds the same energy to every tooth), never raises it:
// the same once-per-revolution burst under 4x more noise scores lower and is still found.
TEST(GearDamage, NoiseLowersTheToothScore) {
  const diag::Gearbox gb = gearbox();
  const auto quiet = detect::locate_gear_damage(synthetic("output", 4, 0.25), gb);
  const auto noisy = detect::locate_gear_damage(synthetic("output", 4, 1.0), gb);
  const auto& q = shaft(quiet, "output");
  const auto& n = shaft(noisy, "output");
  ASSERT_GT(n.snr, 2.0);
  EXPECT_LT(n.score, q.score);
  EXPECT_EQ(quiet.status, "damaged");
  EXPECT_EQ(noisy.status, "damaged");
}

// Pitch errors as the difference signal sees them: a transient at every tooth of a
// gear, with a random amplitude (Gaussian, sigma = A / 3, redrawn beyond A, as the simulator
// draws ISO 1328 pitch deviations). Each transient is impulsive, so the exclusive signal's
// kurtosis is high (the former score flagged such gears), but no tooth stands out among the
// others: healthy. The same pattern with one tooth at 4 A (a local fault among pitch errors) is
// found on its shaft.
std::vector<double> pitch_error_amplitudes(std::uint64_t seed, double a) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, a / 3.0);
  std::vector<double> v(36);
  for (double& x : v) {
    do x = g(rng);
    while (std::abs(x) > a);
  }
  return v;
}

TEST(GearDamage, PitchErrorsOnEveryToothAreNotDamage) {
  const diag::Gearbox gb = gearbox();
  constexpr double kToothAmp = 30.0;  // [m/s^2]
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const auto r =
        detect::locate_gear_damage(synthetic("", seed, kNoiseRms, kMeshAmp, 1.0, kInputHz,
                                             pitch_error_amplitudes(seed, kToothAmp)),
                                   gb);
    const auto& c = shaft(r, "counter");
    EXPECT_GT(c.fm4, 5.0) << "the distributed pattern this test is about is not impulsive";
    EXPECT_EQ(r.status, "healthy") << nlohmann::json(detect::to_json(r)).dump(1);
  }
}

TEST(GearDamage, OneToothStandingOutAmongPitchErrorsIsDamage) {
  const diag::Gearbox gb = gearbox();
  constexpr double kToothAmp = 30.0;  // [m/s^2]
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    std::vector<double> amps = pitch_error_amplitudes(seed, kToothAmp);
    amps[7] = 4.0 * kToothAmp;
    const auto r = detect::locate_gear_damage(
        synthetic("", seed, kNoiseRms, kMeshAmp, 1.0, kInputHz, amps), gb);
    EXPECT_EQ(r.status, "damaged") << nlohmann::json(detect::to_json(r)).dump(1);
    ASSERT_FALSE(r.findings.empty());
    EXPECT_EQ(r.findings[0].shaft, "counter");
  }
}

// A speed estimate off by 3e-5 (the order of what edge jitter leaves after the pulse fit over a
// short record) puts the 18th order of the TSA at 18.00054: within each revolution the mesh line
// no longer closes on itself, and the one-revolution window leaks about A x 5e-4 / |k - 18| into
// the orders beside it, coherently in every revolution. With mesh lines 300x the noise (a
// gearbox near resonance) that is a significant "exclusive" signal on a healthy input shaft:
// SNR 7.9 without the refinement. Following the phase of the strongest mesh line from
// revolution to revolution and correcting the pulses leaves noise alone (1.15; 1 +- 0.4 as in
// MeshTonesAndNoiseAloneAreHealthy).
TEST(GearDamage, ASpeedErrorOfTheTachoIsRefinedFromTheMeshLines) {
  const diag::Gearbox gb = gearbox();
  constexpr double kLoudMesh = 300.0;  // [m/s^2]
  constexpr double kRateError = 3e-5;
  const diag::Recording rec = synthetic("", 3, kNoiseRms, kLoudMesh, 1.0 + kRateError);
  detect::GearDamageOptions raw;
  raw.refine_speed = false;
  const auto unrefined = detect::locate_gear_damage(rec, gb, raw);
  const auto refined = detect::locate_gear_damage(rec, gb);
  const double min_snr = detect::GearDamageOptions{}.min_snr;
  EXPECT_GT(shaft(unrefined, "input").snr, 3.0 * min_snr)
      << "the leakage this test is about is absent";
  EXPECT_EQ(refined.status, "healthy") << nlohmann::json(detect::to_json(refined)).dump(1);
  for (const auto& s : refined.shafts) EXPECT_NEAR(s.snr, 1.0, 0.4) << s.shaft;
}

// The pulses of a 0/1 tacho sampled at fs are late by up to one sampling period, by an amount
// that follows the fractional part of (revolution x samples per revolution): at 267.48 samples
// per revolution it alternates and beats slowly (period 50 revolutions), which the polynomial
// fit of the pulse times cannot remove. A loud mesh line then wanders in phase from revolution
// to revolution and the average keeps part of its leakage in the exclusive orders, coherently:
// without the refinement every shaft here has a significant exclusive signal (SNR 3.5-5.5)
// with a damage-like kurtosis (FM4 8-14, a kurtosis score); only the level gate (its RMS
// is below 0.005 of the mesh lines here) keeps them from being flagged. In the simulated closed
// loop the same error on a resonant 6th mesh harmonic passed the level gate too: the loop's one
// false alarm before this correction. Correcting each revolution from the mesh line's own phase
// leaves noise alone.
TEST(GearDamage, TachoQuantisationIsCorrectedFromTheMeshLinePhase) {
  const diag::Gearbox gb = gearbox();
  constexpr double kLoudMesh = 1000.0;              // [m/s^2], 60 dB over the noise
  constexpr double kBeatingInputHz = kFs / 267.48;  // 37.386 Hz, 2243 rpm
  const diag::Recording rec = synthetic("", 5, kNoiseRms, kLoudMesh, 1.0, kBeatingInputHz);
  detect::GearDamageOptions raw;
  raw.refine_speed = false;
  const auto unrefined = detect::locate_gear_damage(rec, gb, raw);
  const auto refined = detect::locate_gear_damage(rec, gb);
  const detect::GearDamageOptions defaults;
  for (const auto& s : unrefined.shafts) {
    EXPECT_GT(s.snr, 1.5 * defaults.min_snr)
        << s.shaft << ": the error this test is about is absent";
  }
  EXPECT_EQ(refined.status, "healthy") << nlohmann::json(detect::to_json(refined)).dump(1);
  for (const auto& s : refined.shafts) {
    EXPECT_NEAR(s.snr, 1.0, 0.4) << s.shaft << " (noise alone, MeshTonesAndNoiseAloneAreHealthy)";
    EXPECT_EQ(s.score, 1.0) << s.shaft;
  }
}

TEST(GearDamage, ShaftFrequenciesFollowTheTachoAndTheRatios) {
  const auto r = detect::locate_gear_damage(synthetic("", 3), gearbox());
  // The frequency is the pulse count over the pulse span: the edges are known to half a sample
  // (50 us) at each end of a ~2 s span, 5e-5 relative.
  constexpr double kRelTol = 1e-4;
  EXPECT_NEAR(shaft(r, "input").frequency_hz, kInputHz, kRelTol * kInputHz);
  EXPECT_NEAR(shaft(r, "counter").frequency_hz, kInputHz / 2, kRelTol * kInputHz);
  EXPECT_NEAR(shaft(r, "output").frequency_hz, kInputHz / 4, kRelTol * kInputHz);
}

// The three-shaft box has sub-harmonic ratios (the counter's period is 2 x the input's, the
// output's 2 x the counter's and 4 x the input's): said in the note, and a counter fault, which
// folds into the input's average, is put on the counter.
TEST(GearDamage, SubHarmonicRatiosAreSaidAndTheSlowerShaftIsBlamed) {
  const auto r = detect::locate_gear_damage(synthetic("counter", 2), gearbox());
  EXPECT_NE(r.note.find("the period of 'counter' is 2 x that of 'input'"), std::string::npos)
      << r.note;
  EXPECT_NE(r.note.find("the period of 'output' is 4 x that of 'input'"), std::string::npos)
      << r.note;
  ASSERT_FALSE(r.findings.empty());
  EXPECT_EQ(r.findings[0].shaft, "counter");
  if (shaft(r, "input").damaged) {
    EXPECT_NE(r.findings[0].note.find("'input' (period 1/2 of this shaft's) is flagged too"),
              std::string::npos)
        << r.findings[0].note;
  }
}

TEST(GearDamage, JsonFindingsShareTheAttributeKeys) {
  const auto j = detect::to_json(detect::locate_gear_damage(synthetic("counter", 2), gearbox()));
  ASSERT_EQ(j["findings"].size(), 1u);
  for (const char* key : {"shaft", "gears", "confidence", "note", "channel", "score"}) {
    EXPECT_TRUE(j["findings"][0].contains(key)) << key;
  }
  EXPECT_EQ(j["status"], "damaged");
}

TEST(GearDamage, BadOptionsAndInputsAreRefused) {
  detect::GearDamageOptions o;
  o.samples_per_rev = 500;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.damaged_fm4 = o.healthy_fm4 - 1.0;  // below healthy_fm4
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.healthy_fm4 = 0.5;  // below 1 (no tooth stands out)
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.min_snr = 0.5;  // below noise alone
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.band_fraction = 1.5;
  EXPECT_THROW(o.validate(), diag::InputError);
  diag::Recording rec = synthetic("", 1);
  rec.tachos.clear();
  EXPECT_THROW(detect::locate_gear_damage(rec, gearbox()), diag::InputError);
  o = {};
  o.channels["no_such_shaft"] = {"input_bearing1_along_loa"};
  EXPECT_THROW(detect::locate_gear_damage(synthetic("", 1), gearbox(), o), diag::InputError);
}

}  // namespace
