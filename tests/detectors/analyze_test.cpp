// analyze_recording on synthetic recordings with known content: a mesh tone modulated at one
// shaft's rotation, a known two-direction ratio, a bearing's outer-race impacts, and the JSON keys.
#include "detect/analysis/analyze.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <set>

#include "detect/indicators/indicators.hpp"
#include "detect/spectral/fft.hpp"
#include "detect/spectral/spectrum.hpp"
#include "diag/error.hpp"
#include "report/html_report.hpp"
#include "report/report.hpp"
#include "report/svg_plot.hpp"

namespace {

constexpr double kFs = 10000.0;
constexpr double kDuration = 10.0;
constexpr double kInputHz = 10.0;            // 600 rpm
constexpr int kZin = 18, kZout = 25;         // mesh 180 Hz; output 7.2 Hz (not a harmonic of 10)
constexpr double kMeshHz = kZin * kInputHz;  // 180 Hz
constexpr double kOutputHz = kInputHz * kZin / kZout;
constexpr double kNoise = 0.05;      // [m/s^2] Gaussian, per sample
constexpr double kModulation = 0.4;  // AM index of the damaged gear's shaft

const char* kGearbox = R"({"name": "pair",
  "shafts": [{"name": "in"}, {"name": "out"}],
  "gears": [{"name": "a", "shaft": "in", "teeth": 18, "module_mm": 3.0},
            {"name": "b", "shaft": "out", "teeth": 25, "module_mm": 3.0}],
  "meshes": [{"driver": "a", "driven": "b"}],
  "bearings": [{"name": "bearing1", "shaft": "in", "rolling_elements": 9,
                "pitch_diameter_mm": 40, "element_diameter_mm": 8, "contact_angle_deg": 0}],
  "input": {"shaft": "in", "speed_rpm": 600.0, "torque_nm": 50.0}})";

diag::Signal channel(const std::string& name, diag::Direction d, std::vector<double> x) {
  diag::Signal s;
  s.name = name;
  s.fs_hz = kFs;
  s.unit = "m/s^2";
  s.direction = d;
  s.location = "bearing1";
  s.samples = std::move(x);
  return s;
}

// Mesh harmonics 1 and 2 (amplitudes 1 and 0.5), both amplitude-modulated at modulation_hz,
// plus noise; normal channel: 0.1 at the mesh fundamental plus noise. A tacho on "in".
diag::Recording pair_recording(double modulation_hz, unsigned seed = 1) {
  const std::size_t n = static_cast<std::size_t>(kFs * kDuration);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, kNoise);
  std::vector<double> along(n), normal(n), tacho(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kFs;
    const double am = 1 + kModulation * std::cos(2 * M_PI * modulation_hz * t);
    along[i] =
        am * (std::sin(2 * M_PI * kMeshHz * t) + 0.5 * std::sin(4 * M_PI * kMeshHz * t)) + g(rng);
    normal[i] = 0.1 * std::sin(2 * M_PI * kMeshHz * t + 0.7) + g(rng);
    tacho[i] = std::fmod(t * kInputHz, 1.0) < 0.05 ? 1.0 : 0.0;
  }
  diag::Recording r;
  r.signals.push_back(channel("bearing1_along_loa", diag::Direction::kAlongLoa, along));
  r.signals.push_back(channel("bearing1_normal_loa", diag::Direction::kNormalLoa, normal));
  diag::Signal tc = channel("in", diag::Direction::kTacho, tacho);
  tc.location = "in";
  tc.unit = "";
  r.tachos.push_back(tc);
  return r;
}

const diag::Gearbox& gearbox() {
  static const diag::Gearbox gb = diag::parse_gearbox_text(kGearbox, "analyze_test");
  return gb;
}

// The sideband vote's note ("sidebands of mesh a_b (...) point at SHAFT in K of N channels
// ..."), empty when the vote passed no quorum. The vote is never a finding (findings.cpp: healthy
// gears with ordinary pitch errors pass it on every recording).
std::string sideband_vote(const detect::AnalysisResult& r) {
  for (const auto& f : r.findings) EXPECT_NE(f.kind, "gear_sidebands") << f.note;
  for (const auto& n : r.notes) {
    if (n.rfind("sidebands of mesh", 0) == 0 && n.find(") point at ") != std::string::npos)
      return n;
  }
  return {};
}

TEST(Analyze, SidebandsAtTheInputShaftRatePointAtTheInputShaft) {
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  ASSERT_EQ(r.channels.size(), 2u);
  const auto& m = r.channels[0].meshes.at(0);
  EXPECT_EQ(m.sidebands.status, detect::SidebandStatus::kPointed);
  ASSERT_GE(m.sidebands.pointed, 0);
  EXPECT_EQ(m.sidebands.shafts[static_cast<std::size_t>(m.sidebands.pointed)].name, "in");
  const std::string vote = sideband_vote(r);
  EXPECT_NE(vote.find(") point at in in "), std::string::npos) << vote;
  EXPECT_NE(vote.find(" of 2 channels (best bearing1_along_loa"), std::string::npos) << vote;
  EXPECT_NE(vote.find(": a's mesh is modulated"), std::string::npos) << vote;
}

TEST(Analyze, SidebandsAtTheOutputShaftRatePointAtTheOutputShaft) {
  const auto r = detect::analyze_recording(pair_recording(kOutputHz), &gearbox());
  const std::string vote = sideband_vote(r);
  EXPECT_NE(vote.find(") point at out in "), std::string::npos) << vote;
  EXPECT_NE(vote.find(": b's mesh is modulated"), std::string::npos) << vote;
}

TEST(Analyze, ShaftSpeedsComeFromTheTachoAndTheRatio) {
  // Pulse edges are placed to half a sample (50 us) at each end of a 10 s span: 1e-5 relative.
  constexpr double kRelTol = 1e-5;
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  ASSERT_EQ(r.shafts.size(), 2u);
  EXPECT_EQ(r.shafts[0].source, "tacho");
  EXPECT_NEAR(r.shafts[0].speed_hz / kInputHz, 1.0, kRelTol);
  EXPECT_NEAR(r.shafts[1].speed_hz / kOutputHz, 1.0, kRelTol);
  EXPECT_NEAR(r.meshes.at(0).frequency_hz / kMeshHz, 1.0, kRelTol);
}

TEST(Analyze, TsaOfTheInputShaftRecoversTheModulatedMeshTone) {
  // The TSA keeps the orders locked to "in": mesh order 18 at amplitude 1 and its AM sidebands
  // 17 and 19 at kModulation / 2. Tolerance 1 %: resampler passband ripple < 1e-3, noise after
  // 100 revolutions ~ 5e-4 per order line, tacho edges quantised to half a sample (a constant
  // phase, no amplitude loss).
  constexpr double kAmpTol = 0.01;
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  const auto& tsa = r.channels[0].tsa.at(0);
  ASSERT_TRUE(tsa.computed) << tsa.note;
  EXPECT_EQ(tsa.shaft, "in");
  EXPECT_GE(tsa.revolutions, 98);
  const auto a = detect::order_amplitudes(tsa.tsa);
  EXPECT_NEAR(a[kZin], 1.0, kAmpTol);
  EXPECT_NEAR(a[kZin - 1], kModulation / 2, kAmpTol);
  EXPECT_NEAR(a[kZin + 1], kModulation / 2, kAmpTol);
  EXPECT_NEAR(a[2 * kZin], 0.5, kAmpTol);
  ASSERT_EQ(tsa.gears.size(), 1u);
  // SI = (A(z-1) + A(z+1)) / 2 [D02]: kModulation / 2 here.
  EXPECT_NEAR(tsa.gears[0].indicators.si, kModulation / 2, kAmpTol);
  // regular + residual = TSA exactly (tsa.hpp).
  for (std::size_t i = 0; i < tsa.tsa.size(); ++i) {
    EXPECT_NEAR(tsa.regular[i] + tsa.residual[i], tsa.tsa[i], 1e-12);
  }
}

// A simulator-style mesh force without a direction, noise-free and modulated at the OUTPUT
// shaft's rate, beside accelerometers whose sidebands point at the input shaft. The force is
// analysed and shown but does not vote: the finding names the input shaft (with the force
// voting, "in" and "out" would tie 1:1 and nothing would be found), and no note quotes the
// prominence of a noise-free spectrum (its lines reach the detector's 300 dB cap).
TEST(Analyze, ChannelsWithoutADirectionBesideSensorsDoNotVote) {
  auto rec = pair_recording(kInputHz);
  const std::size_t n = rec.signals[0].samples.size();
  std::vector<double> force(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kFs;
    force[i] = 1000 + 100 * (1 + kModulation * std::cos(2 * M_PI * kOutputHz * t)) *
                          std::sin(2 * M_PI * kMeshHz * t);
  }
  diag::Signal f = channel("a_b_force", diag::Direction::kUnspecified, force);
  f.role = diag::Role::kForce;  // the channel contract: a force is no vibration sensor
  f.unit = "N";
  f.location = "a_b";
  rec.signals.push_back(f);
  const auto r = detect::analyze_recording(rec, &gearbox());
  ASSERT_EQ(r.channels.size(), 3u);
  EXPECT_TRUE(r.channels[0].sensor);
  EXPECT_FALSE(r.channels[2].sensor);
  // The force is analysed: its own sidebands point at the output shaft.
  const auto& fm = r.channels[2].meshes.at(0).sidebands;
  ASSERT_EQ(fm.status, detect::SidebandStatus::kPointed);
  EXPECT_EQ(fm.shafts[static_cast<std::size_t>(fm.pointed)].name, "out");
  EXPECT_TRUE(r.channels[2].bearings.empty());  // nor is it a bearing sensor
  // The vote counts the two sensors, not the force; its prominence is a number, not
  // "4.6e+03 dB".
  const std::string vote = sideband_vote(r);
  EXPECT_NE(vote.find(") point at in in "), std::string::npos) << vote;
  EXPECT_NE(vote.find(" of 2 channels (best bearing1_along_loa"), std::string::npos) << vote;
  EXPECT_EQ(vote.find("e+0"), std::string::npos) << vote;
  for (const auto& x : r.findings) EXPECT_NE(x.channel, "a_b_force");
  EXPECT_EQ(report::to_json(r)["channels"][2]["sensor"], false);
}

// Imported measurements carry no direction: every vibration channel is a sensor and votes.
TEST(Analyze, WithoutAnyDirectionEveryVibrationChannelVotes) {
  auto rec = pair_recording(kInputHz);
  for (auto& s : rec.signals) s.direction = diag::Direction::kUnspecified;
  const auto r = detect::analyze_recording(rec, &gearbox());
  for (const auto& c : r.channels) EXPECT_TRUE(c.sensor) << c.name;
  const std::string vote = sideband_vote(r);
  EXPECT_NE(vote.find(") point at in in "), std::string::npos) << vote;
  EXPECT_NE(vote.find(" of 2 channels"), std::string::npos) << vote;
}

TEST(Analyze, TwoDirectionRatioIsTheNormalToAlongEnergyAtTheMeshHarmonics) {
  // along: harmonics 1 and 2 at amplitudes 1 and 0.5 (their AM sidebands lie 10 Hz away, outside
  // the 1.8-3.6 Hz bands); normal: 0.1 at the fundamental. Expected 10 log10(0.01 / 1.25).
  // Noise in the bands: 5e-7 /Hz x 21.6 Hz = 1.1e-5 against 5e-3: 0.01 dB; tolerance 0.1 dB.
  constexpr double kDbTol = 0.1;
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  ASSERT_EQ(r.two_direction.size(), 1u);
  const auto& t = r.two_direction[0];
  EXPECT_EQ(t.along_channel, "bearing1_along_loa");
  EXPECT_EQ(t.normal_channel, "bearing1_normal_loa");
  EXPECT_EQ(t.mesh, "a_b");
  EXPECT_NEAR(t.comparison.normal_to_along_db, 10 * std::log10(0.01 / 1.25), kDbTol);
}

// analyze keeps an LOA channel's spectrum only up to the two-direction stage's highest band:
// the comparison is the same bytes as on the whole spectra, with the default bands, wide ones,
// and harmonics past Nyquist (invalid, as on the whole spectrum).
TEST(Analyze, TwoDirectionOnTheKeptBinsEqualsTheWholeSpectra) {
  const auto rec = pair_recording(kInputHz);
  detect::SpectrumOptions so;
  so.fs_hz = kFs;
  so.window = detect::WindowType::kHann;
  so.remove_mean = true;
  so.nfft = detect::next_fast_length(rec.signals[0].samples.size());
  const detect::Spectrum sa = detect::amplitude_spectrum(rec.signals[0].samples, so);
  const detect::Spectrum sn = detect::amplitude_spectrum(rec.signals[1].samples, so);
  for (int harmonics : {3, 40}) {
    for (double halfwidth : {0.0, 50.0}) {
      detect::AnalyzeOptions opt;
      opt.two_direction.mesh_harmonics = harmonics;
      opt.two_direction.halfwidth_hz = halfwidth;
      const auto r = detect::analyze_recording(rec, &gearbox(), opt);
      ASSERT_EQ(r.two_direction.size(), 1u);
      const auto want = detect::compare_two_directions(
          {sa.frequency_hz, sa.amplitude}, {sn.frequency_hz, sn.amplitude},
          sa.enbw_hz / sa.resolution_hz, r.meshes[0].frequency_hz, opt.two_direction);
      const auto& got = r.two_direction[0].comparison;
      ASSERT_EQ(got.harmonics.size(), want.harmonics.size());
      int invalid = 0;
      for (std::size_t h = 0; h < want.harmonics.size(); ++h) {
        EXPECT_EQ(got.harmonics[h].valid, want.harmonics[h].valid) << h;
        EXPECT_EQ(got.harmonics[h].along, want.harmonics[h].along) << h;
        EXPECT_EQ(got.harmonics[h].normal, want.harmonics[h].normal) << h;
        invalid += want.harmonics[h].valid ? 0 : 1;
      }
      EXPECT_EQ(got.normal_to_along_db, want.normal_to_along_db);
      EXPECT_EQ(invalid > 0, harmonics == 40);  // 28 x 180 Hz > 5 kHz
    }
  }
}

TEST(Analyze, TimeIndicatorsMatchANaiveComputation) {
  constexpr double kRelTol = 1e-12;  // two-pass sums over 1e5 samples
  const auto rec = pair_recording(kInputHz);
  const auto r = detect::analyze_recording(rec, nullptr);
  const auto& x = rec.signals[0].samples;
  double ss = 0, pk = 0;
  for (double v : x) ss += v * v, pk = std::max(pk, std::abs(v));
  const double rms = std::sqrt(ss / static_cast<double>(x.size()));
  EXPECT_NEAR(r.channels[0].time.rms, rms, kRelTol * rms);
  EXPECT_NEAR(r.channels[0].time.crest_factor, pk / rms, kRelTol * pk / rms);
  // Without a gearbox: no gear-related output, the largest line is the mesh fundamental.
  EXPECT_TRUE(r.channels[0].meshes.empty());
  EXPECT_TRUE(r.two_direction.empty());
  EXPECT_TRUE(r.findings.empty());
  ASSERT_FALSE(r.channels[0].spectrum_peaks.empty());
  EXPECT_NEAR(r.channels[0].spectrum_peaks[0].frequency_hz, kMeshHz, 0.1);
}

TEST(Analyze, OuterRaceImpactsAtBpfoAreReportedAsABearingFinding) {
  // BPFO = n f_r / 2 (1 - B_d/P_d) = 9 x 10 / 2 x 0.8 = 36 Hz. Impacts ring a 2.5 kHz resonance
  // (1 ms decay) on a vertical channel at bearing1; the kurtogram finds the band. The impact
  // spacing jitters by 0.5 % (rolling elements slip): a strictly periodic train sampled at 10 kHz
  // repeats its sub-sample phase pattern every 9 impacts, i.e. at exactly FTF = BPFO / 9, and
  // diagnose_bearings_from_signal rightly sees a cage family too (ambiguous: no finding).
  const double bpfo = 9 * kInputHz / 2 * (1 - 8.0 / 40.0);
  auto rec = pair_recording(kInputHz);
  const std::size_t n = rec.signals[0].samples.size();
  std::vector<double> v(n, 0.0);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, kNoise);
  for (std::size_t i = 0; i < n; ++i) v[i] = g(rng);
  std::normal_distribution<double> slip(0.0, 0.005);
  for (double t0 = 0.01; t0 < kDuration; t0 += (1 + slip(rng)) / bpfo) {
    for (std::size_t i = static_cast<std::size_t>(t0 * kFs); i < n; ++i) {
      const double t = static_cast<double>(i) / kFs - t0;
      if (t > 0.01) break;
      v[i] += 1.0 * std::exp(-t / 1e-3) * std::sin(2 * M_PI * 2500 * t);
    }
  }
  rec.signals.push_back(channel("bearing1_vertical", diag::Direction::kVertical, v));
  const auto r = detect::analyze_recording(rec, &gearbox());
  const auto& c = r.channels[2];
  EXPECT_LE(c.envelope_low_hz, 2500.0);  // the demodulation band holds the resonance
  EXPECT_GE(c.envelope_high_hz, 2500.0);
  bool found = false;
  for (const auto& f : r.findings) {
    if (f.kind != "bearing") continue;
    found = true;
    EXPECT_EQ(f.bearing, "bearing1");
    EXPECT_EQ(diag::to_string(f.fault), "outer_race");
    EXPECT_NEAR(f.frequency_hz, bpfo, 1e-3 * bpfo);  // tacho speed to 1e-5
    EXPECT_EQ(f.channel, "bearing1_vertical");
  }
  EXPECT_TRUE(found);
}

TEST(Analyze, JsonKeysAreStable) {
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  const auto j = report::to_json(r);
  for (const char* k : {"format", "format_version", "gearbox", "input_shaft", "duration_s",
                        "shafts", "meshes", "channels", "two_direction", "findings", "notes"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_FALSE(j.contains("anomaly_score"));  // no baseline given
  const auto& c = j["channels"][0];
  for (const char* k :
       {"name", "unit", "direction", "location", "fs_hz", "samples", "vibration", "indicators",
        "spectrum", "psd", "envelope", "meshes", "tsa", "bearings", "notes"}) {
    EXPECT_TRUE(c.contains(k)) << k;
  }
  for (const char* k : {"rms", "peak", "crest_factor", "kurtosis", "skewness"}) {
    EXPECT_TRUE(c["indicators"].contains(k)) << k;
  }
  for (const char* k : {"fm0", "fm4", "m6a", "m8a", "na4", "er", "ser", "slf", "si"}) {
    EXPECT_TRUE(c["tsa"][0]["gears"][0].contains(k)) << k;
  }
  EXPECT_EQ(c["meshes"][0]["sidebands"]["pointed_shaft"], "in");
  ASSERT_EQ(c["bearings"].size(), 1u);  // bearing1, on the channels located at it
  for (const char* k : {"diagnosed", "status", "fault", "band_centre_hz", "band_width_hz",
                        "families", "whole_band_families"}) {
    EXPECT_TRUE(c["bearings"][0]["decision"].contains(k)) << k;
  }
  // The modulated pair draws no finding (the sideband vote is a note); a finding's keys are
  // checked on one the locator would make.
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
  auto with_finding = r;
  detect::Finding gf;
  gf.kind = "gear_damage";
  gf.fault = diag::FaultKind::kToothDamage;
  gf.shaft = "in";
  gf.gears = {"a"};
  gf.frequency_hz = kInputHz;
  gf.channel = "bearing1_along_loa";
  gf.confidence = 0.5;
  gf.note = "a tooth of a stands out";
  with_finding.findings.push_back(gf);
  const auto f = report::to_json(with_finding)["findings"].at(0);
  for (const char* k :
       {"kind", "fault", "shaft", "gears", "frequency_hz", "channel", "confidence", "note"}) {
    EXPECT_TRUE(f.contains(k)) << k;
  }
  for (const char* k : {"location", "along_channel", "normal_channel", "mesh", "mesh_hz",
                        "along_energy", "normal_energy", "normal_to_along_db", "harmonics"}) {
    EXPECT_TRUE(j["two_direction"][0].contains(k)) << k;
  }
  // Same input, same bytes.
  EXPECT_EQ(
      j.dump(),
      report::to_json(detect::analyze_recording(pair_recording(kInputHz), &gearbox())).dump());
}

TEST(Analyze, ResultDoesNotDependOnTheThreadCount) {
  auto rec = pair_recording(kInputHz);
  rec.signals.push_back(rec.signals[0]);
  rec.signals.back().name = "copy";
  rec.signals.back().location = "elsewhere";
  detect::AnalyzeOptions one, four;
  one.threads = 1;
  four.threads = 4;
  EXPECT_EQ(report::to_json(detect::analyze_recording(rec, &gearbox(), one)).dump(),
            report::to_json(detect::analyze_recording(rec, &gearbox(), four)).dump());
}

// A record whose length has a large prime factor (here prime: 20011 samples) is transformed
// zero-padded to next_fast_length (analyze.hpp): the bins are fs / nfft apart, the window's
// ENBW is the record's (1.5 bins of fs / n for Hann), and a tone reads its amplitude within
// Hann's scalloping loss (at most 15.2 %, 1.42 dB, half a bin off a line) at the bin nearest it.
TEST(Analyze, SpectrumOfAPrimeLengthRecordIsZeroPaddedToAFastLength) {
  constexpr std::size_t n = 20011;
  constexpr double f0 = 123.4, a0 = 2.0;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = a0 * std::sin(2 * M_PI * f0 * i / kFs);
  diag::Recording rec;
  rec.signals.push_back(channel("acc", diag::Direction::kVertical, x));
  const auto r = detect::analyze_recording(rec, nullptr, {});
  const detect::ChannelAnalysis& c = r.channels.at(0);
  const std::size_t nfft = detect::next_fast_length(n);
  ASSERT_EQ(nfft, 20160u);  // 2^6 3^2 5 7
  EXPECT_EQ(c.spectrum_resolution_hz, kFs / static_cast<double>(nfft));
  EXPECT_NEAR(c.spectrum_enbw_hz, 1.5 * kFs / static_cast<double>(n), 1e-9);
  ASSERT_FALSE(c.spectrum_peaks.empty());
  EXPECT_NEAR(c.spectrum_peaks[0].frequency_hz, f0, 0.5 * c.spectrum_resolution_hz + 1e-9);
  EXPECT_LE(c.spectrum_peaks[0].amplitude, a0 * (1 + 1e-3));
  EXPECT_GE(c.spectrum_peaks[0].amplitude, a0 * (1 - 0.152));
}

// AnalyzeOptions::traces = false (the CLI without --html or --curves): the JSON, the findings and
// the notes are the same bytes as with the traces, the plot-only curves are empty, and the PSD's
// resolution and segment count (set from the Welch layout, not computed) are the computed ones.
TEST(Analyze, WithoutTracesTheReportIsTheSameAndThePlotCurvesAreEmpty) {
  const auto rec = pair_recording(kInputHz);
  detect::AnalyzeOptions with, without;
  without.traces = false;
  const auto a = detect::analyze_recording(rec, &gearbox(), with);
  const auto b = detect::analyze_recording(rec, &gearbox(), without);
  EXPECT_EQ(report::to_json(a).dump(), report::to_json(b).dump());
  ASSERT_EQ(a.channels.size(), b.channels.size());
  std::size_t spectra = 0;
  for (std::size_t i = 0; i < a.channels.size(); ++i) {
    const auto &ca = a.channels[i], &cb = b.channels[i];
    if (!ca.vibration) continue;
    ++spectra;
    EXPECT_FALSE(ca.spectrum.x.empty());
    EXPECT_FALSE(ca.psd.x.empty());
    EXPECT_FALSE(ca.order_spectrum.x.empty());
    EXPECT_GT(ca.spectrogram.time_s.size(), 1u);
    EXPECT_TRUE(cb.spectrum.x.empty() && cb.psd.x.empty() && cb.order_spectrum.x.empty());
    EXPECT_TRUE(cb.spectrogram.time_s.empty());
    EXPECT_GT(ca.psd_segments, 1u);
    EXPECT_EQ(ca.psd_segments, cb.psd_segments);
    EXPECT_EQ(ca.psd_resolution_hz, cb.psd_resolution_hz);
    for (std::size_t m = 0; m < ca.meshes.size(); ++m) {
      EXPECT_FALSE(ca.meshes[m].zoom.x.empty());
      EXPECT_TRUE(cb.meshes[m].zoom.x.empty());
    }
  }
  EXPECT_EQ(spectra, 2u);
}

// --timing: the wall time per stage and the CPU time of each per-channel stage summed over the
// channels (channel_cpu.*, every one of the nine stages, >= 0, together at most the process's
// CPU time since the start); without it no timing_s at all (the JSON stays byte-deterministic).
TEST(Analyze, TimingGivesEachChannelStagesCpuAndIsAbsentOtherwise) {
  const auto rec = pair_recording(kInputHz);
  detect::AnalyzeOptions opt;
  opt.threads = 1;
  EXPECT_FALSE(
      report::to_json(detect::analyze_recording(rec, &gearbox(), opt)).contains("timing_s"));
  opt.timing = true;
  const detect::AnalysisResult r = detect::analyze_recording(rec, &gearbox(), opt);
  double sum = 0;
  for (const char* stage : {"time", "spectral_record", "spectra", "spectrogram", "envelope",
                            "bearing", "sidebands", "order_spectrum", "tsa"}) {
    const auto it = r.timing_s.find(std::string("channel_cpu.") + stage);
    ASSERT_NE(it, r.timing_s.end()) << stage;
    EXPECT_GE(it->second, 0.0) << stage;
    sum += it->second;
  }
  EXPECT_GT(r.timing_s.at("channel_cpu.spectra"), 0.0);
  EXPECT_LE(sum, static_cast<double>(std::clock()) / CLOCKS_PER_SEC + 0.01);
  for (const char* stage : {"kinematics", "angle_plans", "channels", "findings"}) {
    EXPECT_TRUE(r.timing_s.contains(stage)) << stage;
  }
}

TEST(Analyze, HtmlReportIsOneSelfContainedDocument) {
  const auto r = detect::analyze_recording(pair_recording(kInputHz), &gearbox());
  const std::string h = report::render_html_report(r);
  EXPECT_EQ(h.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(h.find("</html>"), std::string::npos);
  EXPECT_EQ(h.find("<script"), std::string::npos);
  EXPECT_EQ(h.find("http://"), h.find("http://www.w3.org/2000/svg"));  // only the SVG namespace
  EXPECT_NE(h.find("<svg"), std::string::npos);
  EXPECT_NE(h.find("Two directions"), std::string::npos);
  EXPECT_NE(h.find("TSA of shaft in"), std::string::npos);
}

// The spectrogram of a tone switched on half-way: the tone's bin is dark before and bright after
// (by more than 60 dB: the record before is exactly zero but for 1e-6 noise); the grid stays
// within its bounds for a record of 2^18 samples (2047 segments) (kSpectrogramColumns spans,
// kSpectrogramRows + 1 bins), and the report draws it as one PNG image.
TEST(Analyze, SpectrogramShowsWhenAToneStartsOnABoundedGrid) {
  const std::size_t n = std::size_t{1} << 18;
  const double fs = 8192, f0 = 1024;  // f0 on bin 32 of the 256-sample segments
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 1e-6);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = noise(rng) + (i >= n / 2 ? std::sin(2 * std::numbers::pi * f0 * i / fs) : 0.0);
  }
  diag::Recording rec;
  diag::Signal s = channel("a", diag::Direction::kUnspecified, std::move(x));
  s.fs_hz = fs;
  rec.signals.push_back(std::move(s));
  const auto r = detect::analyze_recording(rec, nullptr);
  const detect::SpectrogramTrace& sg = r.channels[0].spectrogram;
  ASSERT_EQ(sg.time_s.size(), detect::kSpectrogramColumns);
  ASSERT_EQ(sg.frequency_hz.size(), detect::kSpectrogramRows + 1);
  ASSERT_EQ(sg.psd_db.size(), sg.time_s.size() * sg.frequency_hz.size());
  EXPECT_DOUBLE_EQ(sg.frequency_hz[32], f0);
  const std::size_t bins = sg.frequency_hz.size();
  EXPECT_GT(sg.psd_db[200 * bins + 32] - sg.psd_db[20 * bins + 32], 60.0);
  EXPECT_NEAR(sg.time_s.back(), (n - 0.5 * n / detect::kSpectrogramColumns) / fs, 1e-3);
  const std::string h = report::render_html_report(r);
  EXPECT_NE(h.find("Spectrogram"), std::string::npos);
  EXPECT_NE(h.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);  // PNG signature
}

TEST(Analyze, ShortRecordsSkipStepsWithNotesInsteadOfFailing) {
  auto rec = pair_recording(kInputHz);
  for (auto& s : rec.signals) s.samples.resize(2000);  // 0.2 s: 2 input revolutions
  for (auto& s : rec.tachos) s.samples.resize(2000);
  const auto r = detect::analyze_recording(rec, &gearbox());
  EXPECT_FALSE(r.channels[0].tsa.at(0).computed);
  EXPECT_FALSE(r.channels[0].tsa.at(0).note.empty());
}

TEST(Analyze, BadInputIsRefused) {
  diag::Recording empty;
  EXPECT_THROW(detect::analyze_recording(empty, nullptr), diag::InputError);
  detect::AnalyzeOptions o;
  o.plot_points = 2;
  EXPECT_THROW(detect::analyze_recording(pair_recording(kInputHz), nullptr, o), diag::InputError);
}

TEST(SvgPlot, DecimationKeepsANarrowLine) {
  std::vector<double> x(100000), y(100000, 1e-3);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i);
  y[54321] = 5.0;
  const auto t = detect::decimate_for_plot(x, y, 1000);
  EXPECT_LE(t.x.size(), 1000u);
  EXPECT_EQ(*std::max_element(t.y.begin(), t.y.end()), 5.0);
  const auto k = std::find(t.y.begin(), t.y.end(), 5.0) - t.y.begin();
  EXPECT_EQ(t.x[static_cast<std::size_t>(k)], 54321.0);
}

TEST(SvgPlot, MaxOnlyDecimationKeepsEachBucketsLargestValue) {
  std::vector<double> x(1000), y(1000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i), y[i] = (i % 7) * 1.0;
  const auto t = detect::decimate_for_plot(x, y, 100, detect::Decimation::kMax);
  ASSERT_EQ(t.y.size(), 100u);
  for (double v : t.y) EXPECT_EQ(v, 6.0);  // every 10-sample bucket holds a 6
}

// Both modes against the plain definition (each bucket's first smallest and first largest
// value, in index order; max-only: the first largest), on values with many ties, infinities
// and NaNs (skipped, except a NaN first in its bucket, which a scan in index order keeps).
TEST(SvgPlot, DecimationTakesTheFirstExtremesOfEachBucket) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> level(0, 9);
  std::vector<double> x(10007), y(10007);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i), y[i] = level(rng);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  y[0] = nan;  // first of bucket 0 in both modes
  y[501] = nan;
  y[777] = std::numeric_limits<double>::infinity();
  y[778] = -std::numeric_limits<double>::infinity();
  for (const auto mode : {detect::Decimation::kMax, detect::Decimation::kMinMax}) {
    const std::size_t max_points = 300;
    const auto t = detect::decimate_for_plot(x, y, max_points, mode);
    const bool max_only = mode == detect::Decimation::kMax;
    const std::size_t buckets = max_only ? max_points : max_points / 2;
    std::vector<double> want;
    for (std::size_t b = 0; b < buckets; ++b) {
      const std::size_t i0 = b * x.size() / buckets, i1 = (b + 1) * x.size() / buckets;
      std::size_t lo = i0, hi = i0;
      for (std::size_t i = i0; i < i1; ++i) {
        if (y[i] < y[lo]) lo = i;
        if (y[i] > y[hi]) hi = i;
      }
      if (max_only) {
        want.push_back(x[hi]);
      } else {
        want.push_back(x[std::min(lo, hi)]);
        if (lo != hi) want.push_back(x[std::max(lo, hi)]);
      }
    }
    EXPECT_EQ(t.x, want);
    for (std::size_t k = 0; k < t.x.size(); ++k) {
      const double want_y = y[static_cast<std::size_t>(t.x[k])];
      if (std::isnan(want_y)) {
        EXPECT_TRUE(std::isnan(t.y[k]));
      } else {
        EXPECT_EQ(t.y[k], want_y);
      }
    }
  }
}

TEST(SvgPlot, NiceTicksAreOneTwoFiveSteps) {
  const auto t = report::nice_ticks(0, 97, 5);
  ASSERT_FALSE(t.empty());
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_NEAR(t[1] - t[0], 20.0, 1e-12);
  EXPECT_LE(t.back(), 97.0);
}

}  // namespace
