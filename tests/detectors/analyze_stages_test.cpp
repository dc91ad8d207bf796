// The stage tables of analyze_recording (detectors/src/analysis/stages.hpp, analyze.cpp): each
// recording-level stage announces itself once, in order, and only when its needs are met; each
// channel stage runs only on the channels that meet its needs (a skipped stage costs no CPU
// time, so its channel_cpu entry is exactly 0).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace {

constexpr double kFs = 5000.0;
constexpr double kInputHz = 10.0;  // 600 rpm, the description's nominal speed

const char* kGearbox = R"({"name": "pair",
  "shafts": [{"name": "in"}, {"name": "out"}],
  "gears": [{"name": "a", "shaft": "in", "teeth": 18, "module_mm": 3.0},
            {"name": "b", "shaft": "out", "teeth": 25, "module_mm": 3.0}],
  "meshes": [{"driver": "a", "driven": "b"}],
  "bearings": [{"name": "bearing1", "shaft": "in", "rolling_elements": 9,
                "pitch_diameter_mm": 40, "element_diameter_mm": 8, "contact_angle_deg": 0}],
  "input": {"shaft": "in", "speed_rpm": 600.0, "torque_nm": 50.0}})";

diag::Signal signal(const std::string& name, diag::Role role, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 0.05);
  diag::Signal s;
  s.name = name;
  s.fs_hz = kFs;
  s.unit = role == diag::Role::kForce ? "N" : "m/s^2";
  s.role = role;
  s.location = "bearing1";
  s.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kFs;
    s.samples[i] = std::sin(2 * M_PI * 18 * kInputHz * t) + g(rng);
  }
  return s;
}

// A vibration sensor of 3 s (30 revolutions of the input), a simulated mesh force (analysed,
// never a sensor) and a 40-sample vibration channel (too short for spectra).
diag::Recording recording() {
  diag::Recording r;
  r.signals.push_back(signal("a1", diag::Role::kVibration, 15000, 1));
  r.signals.push_back(signal("force", diag::Role::kForce, 15000, 2));
  r.signals.push_back(signal("short", diag::Role::kVibration, 40, 3));
  return r;
}

struct Analysed {
  detect::AnalysisResult result;
  std::vector<std::string> progress;
};

Analysed analyze(const diag::Gearbox* gb) {
  detect::AnalyzeOptions opt;
  opt.threads = 1;
  opt.timing = true;
  Analysed run;
  opt.progress = [&run](const std::string& stage) { run.progress.push_back(stage); };
  run.result = detect::analyze_recording(recording(), gb, opt);
  return run;
}

const char* const kChannelStages[] = {"time",        "spectral_record", "spectra",
                                      "spectrogram", "envelope",        "bearing",
                                      "sidebands",   "order_spectrum",  "tsa"};

TEST(AnalyzeStages, EachRecordStageIsAnnouncedOnceInOrderWithAGearbox) {
  const diag::Gearbox gb = diag::parse_gearbox_text(kGearbox, "analyze_stages_test");
  const Analysed run = analyze(&gb);
  const std::vector<std::string> expected{"kinematics",    "angle_plans", "channels",
                                          "two_direction", "gear_damage", "findings"};
  EXPECT_EQ(run.progress, expected);
  for (const std::string& stage : expected) EXPECT_TRUE(run.result.timing_s.contains(stage));
  for (const char* stage : kChannelStages) {
    EXPECT_TRUE(run.result.timing_s.contains(std::string("channel_cpu.") + stage)) << stage;
  }
  // The gearbox stages ran on the sensor: its bearing and TSA rows are filled.
  const detect::ChannelAnalysis& a1 = run.result.channels[0];
  EXPECT_EQ(a1.bearings.size(), 1u);
  EXPECT_FALSE(a1.tsa.empty());
  EXPECT_EQ(a1.meshes.size(), 1u);
  // The force channel is analysed but is no sensor: no bearing diagnosis, yet sidebands.
  const detect::ChannelAnalysis& force = run.result.channels[1];
  EXPECT_FALSE(force.sensor);
  EXPECT_TRUE(force.bearings.empty());
  EXPECT_EQ(force.meshes.size(), 1u);
}

TEST(AnalyzeStages, WithoutAGearboxOnlyTheStagesThatNeedNoneRun) {
  const Analysed run = analyze(nullptr);
  const std::vector<std::string> expected{"angle_plans", "channels"};
  EXPECT_EQ(run.progress, expected);
  const auto& t = run.result.timing_s;
  for (const char* stage : {"kinematics", "two_direction", "gear_damage", "findings"}) {
    EXPECT_FALSE(t.contains(stage)) << stage;
  }
  // Never run, so exactly no CPU time; the ones that ran on a 15000-sample channel took some.
  for (const char* stage : {"bearing", "sidebands", "order_spectrum", "tsa"}) {
    EXPECT_EQ(t.at(std::string("channel_cpu.") + stage), 0.0) << stage;
  }
  EXPECT_GT(t.at("channel_cpu.spectra"), 0.0);
  for (const detect::ChannelAnalysis& c : run.result.channels) {
    EXPECT_TRUE(c.meshes.empty()) << c.name;
    EXPECT_TRUE(c.tsa.empty()) << c.name;
  }
}

TEST(AnalyzeStages, AChannelTooShortForSpectraStopsAfterItsTimeIndicators) {
  const Analysed run = analyze(nullptr);
  const detect::ChannelAnalysis& c = run.result.channels[2];
  EXPECT_EQ(c.samples, 40u);
  EXPECT_GT(c.time.rms, 0.0);
  EXPECT_EQ(c.notes, std::vector<std::string>{"fewer than 64 samples: no spectra"});
  EXPECT_TRUE(c.spectrum_peaks.empty());
  EXPECT_TRUE(c.waveform.x.empty());  // the envelope stage (which keeps it) did not run
  EXPECT_TRUE(std::isnan(c.kurtogram_level));
}

}  // namespace
