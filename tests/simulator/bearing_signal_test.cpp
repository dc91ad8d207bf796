// The bearing-fault signal generator (its rates: diag::bearing_rates, tests/libdiag/
// bearing_rates_test.cpp): impact counts, the SNR it promises, determinism, and the envelope lines
// each class must (and must not) carry.
#include "sim/bearing/bearing_signal.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "detect/gear/fault_bands.hpp"
#include "detect/spectral/envelope.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/bearing_rates.hpp"
#include "diag/io/truth.hpp"

namespace {

diag::BearingSpec skf6205() { return diag::skf6205("de"); }

// Noise-free signal of one class: impacts (or the cage's modulated noise) and nothing else.
sim::BearingSignal clean(sim::BearingFaultKind k, std::uint64_t seed = 1) {
  sim::BearingSignalOptions o;
  o.fault = k;
  o.snr_db = 60;  // noise 60 dB under the fault: the envelope's lines are the model's alone
  o.jitter = 0.0;
  o.mean_slip = 0.0;
  o.duration_s = 4.0;
  o.seed = seed;
  return sim::simulate_bearing_signal(skf6205(), o);
}

// The truth names the fault in the vocabulary (diag/io/truth.hpp), the healthy signal none.
TEST(BearingSignal, TheTruthIsTypedWithTheVocabularysName) {
  const auto t = diag::SimulationTruth::from_json(
      clean(sim::BearingFaultKind::kRollingElement).truth, "bearing");
  EXPECT_EQ(t.kind, "bearing");
  ASSERT_EQ(t.defects.size(), 1u);
  EXPECT_EQ(t.defects[0].kind, diag::FaultKind::kRollingElement);
  EXPECT_EQ(t.defects[0].bearing, skf6205().name);
  EXPECT_TRUE(t.extra.contains("rates"));
  EXPECT_TRUE(diag::SimulationTruth::from_json(clean(sim::BearingFaultKind::kNone).truth, "b")
                  .defects.empty());
}

// Prominence of the squared-envelope line near f_hz over its local floor [dB], the envelope
// taken over the resonance band (2-4 kHz around the default 3 kHz).
double envelope_line_db(const sim::BearingSignal& s, double f_hz) {
  detect::BandOptions band;
  band.fs_hz = s.signal.fs_hz;
  band.low_hz = 2000;
  band.high_hz = 4000;
  std::vector<double> e = detect::band_envelope(s.signal.samples, band);
  double mean = 0;
  for (double& v : e) mean += (v *= v);
  mean /= static_cast<double>(e.size());
  for (double& v : e) v -= mean;
  detect::SpectrumOptions so;
  so.fs_hz = s.signal.fs_hz;
  so.window = detect::WindowType::kHann;
  const detect::Spectrum sp = detect::amplitude_spectrum(e, so);
  const detect::SpectrumView view{sp.frequency_hz, sp.amplitude};
  const double df = sp.frequency_hz[1] - sp.frequency_hz[0];
  return detect::measure_line(view, f_hz, 2 * df, 30 * df).prominence_db;
}

}  // namespace

TEST(BearingSignal, OuterRaceGivesOneImpactPerBpfoPeriod) {
  const auto s = clean(sim::BearingFaultKind::kOuterRace);
  // The train starts at a random phase in the first period: floor or ceil of duration x BPFO.
  const double expected = 4.0 * s.rates.bpfo_hz;
  EXPECT_GE(s.impacts, std::floor(expected) - 1);
  EXPECT_LE(s.impacts, std::ceil(expected) + 1);
}

TEST(BearingSignal, NoiseIsSetByTheSnr) {
  sim::BearingSignalOptions o;
  o.fault = sim::BearingFaultKind::kInnerRace;
  o.snr_db = -10;
  const auto s = sim::simulate_bearing_signal(skf6205(), o);
  constexpr double kRelTol = 1e-12;  // set by construction from the fault's measured power
  EXPECT_NEAR(s.fault_rms * s.fault_rms / (s.noise_rms * s.noise_rms), 0.1, 0.1 * kRelTol);
  // The recorded signal's power is fault + noise (independent): 1.1 noise powers, within the
  // sampling error of 48 000 Gaussian samples' power (~0.7 %, 4 sigma = 3 %).
  double p = 0;
  for (double v : s.signal.samples) p += v * v;
  p /= static_cast<double>(s.signal.samples.size());
  EXPECT_NEAR(p / (s.noise_rms * s.noise_rms), 1.1, 0.03 * 1.1);
}

TEST(BearingSignal, SameSeedSameSamplesOtherSeedOthers) {
  const auto a = clean(sim::BearingFaultKind::kRollingElement, 7);
  const auto b = clean(sim::BearingFaultKind::kRollingElement, 7);
  const auto c = clean(sim::BearingFaultKind::kRollingElement, 8);
  EXPECT_EQ(a.signal.samples, b.signal.samples);
  EXPECT_NE(a.signal.samples, c.signal.samples);
}

// A ball spall strikes at 2 BSF, load-modulated at the cage rate: lines at 2 BSF and 2 BSF +- FTF
// and at FTF. Thresholds: 20 dB is far above anything a noise-free record's leakage floor gives
// by chance, and far below the 40-80 dB such lines stand at.
TEST(BearingSignal, BallFaultEnvelopeHasTheBallLineWithCageSidebands) {
  constexpr double kLineDb = 20;
  const auto s = clean(sim::BearingFaultKind::kRollingElement);
  const auto& r = s.rates;
  EXPECT_GT(envelope_line_db(s, r.ball_fault_hz), kLineDb);
  EXPECT_GT(envelope_line_db(s, r.ball_fault_hz + r.ftf_hz), kLineDb);
  EXPECT_GT(envelope_line_db(s, r.ball_fault_hz - r.ftf_hz), kLineDb);
  EXPECT_GT(envelope_line_db(s, r.ftf_hz), kLineDb);
  // The inner strikes are weaker than the outer ones: the alternation puts a line at BSF itself.
  EXPECT_GT(envelope_line_db(s, r.bsf_hz), kLineDb);
}

// Inner race: BPFI with shaft-rate sidebands; outer race at the load zone's centre: BPFO with no
// cage or shaft modulation; cage: FTF and nothing at 2 BSF or BPFO. "Nothing" = under 10 dB
// (noise-free leakage and the cage's random excitation stay well under it).
TEST(BearingSignal, EachClassCarriesItsOwnEnvelopeLinesOnly) {
  constexpr double kLineDb = 20, kNothingDb = 10;
  const auto in = clean(sim::BearingFaultKind::kInnerRace);
  EXPECT_GT(envelope_line_db(in, in.rates.bpfi_hz), kLineDb);
  EXPECT_GT(envelope_line_db(in, in.rates.bpfi_hz + in.rates.shaft_hz), kLineDb);
  const auto out = clean(sim::BearingFaultKind::kOuterRace);
  EXPECT_GT(envelope_line_db(out, out.rates.bpfo_hz), kLineDb);
  EXPECT_LT(envelope_line_db(out, out.rates.bpfo_hz + out.rates.shaft_hz), kNothingDb);
  const auto cage = clean(sim::BearingFaultKind::kCage);
  EXPECT_GT(envelope_line_db(cage, cage.rates.ftf_hz), kLineDb);
  EXPECT_LT(envelope_line_db(cage, cage.rates.ball_fault_hz), kNothingDb);
  EXPECT_LT(envelope_line_db(cage, cage.rates.bpfo_hz), kNothingDb);
}

TEST(BearingSignal, RejectsBadOptionsNamingTheField) {
  sim::BearingSignalOptions o;
  o.resonance_hz = 7000;  // above 0.45 fs
  try {
    sim::simulate_bearing_signal(skf6205(), o);
    FAIL() << "no throw";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("resonance_hz"), std::string::npos) << e.what();
  }
  o = {};
  o.jitter = 0.5;
  EXPECT_THROW(sim::simulate_bearing_signal(skf6205(), o), diag::InputError);
  diag::BearingSpec b = skf6205();
  b.element_diameter_m = 0.05;
  EXPECT_THROW(sim::simulate_bearing_signal(b, {}), diag::InputError);
}
