// detect::analyze_file, the one entry of `analyze`, `batch` and the Python module: it must give
// exactly what its steps give when called one by one (read, speed, channel setup, analysis, notes,
// baselines), read long HDF5 recordings in part with the whole file behind the means, and name
// the file at fault in every error.
#include "detect/analysis/analyze_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/channel_setup.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/open_recording.hpp"
#include "report/report.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kFs = 8000.0;

// Noise plus a 3 kHz carrier modulated at 37 Hz (an envelope line), with a 1-pulse-per-rev tacho
// at 25 Hz described as the input shaft's.
diag::Recording synthetic(std::size_t n, std::uint64_t seed, double fs = kFs) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 0.3);
  diag::Recording rec;
  rec.signals.resize(2);  // both first: a reference into the vector stays valid
  diag::Signal& s = rec.signals[0];
  s.name = "acc";
  s.fs_hz = fs;
  s.unit = "m/s^2";
  s.samples.resize(n);
  diag::Signal& k = rec.signals[1];
  k.name = "key";
  k.fs_hz = fs;
  k.unit = "V";
  k.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs;
    s.samples[i] = g(rng) + (1 + std::cos(2 * std::numbers::pi * 37 * t)) *
                                std::sin(2 * std::numbers::pi * 3000 * t);
    k.samples[i] = std::fmod(t * 25.0, 1.0) < 0.1 ? 5.0 : 0.0;
  }
  return rec;
}

const char* kGearbox = R"({"name": "one", "shafts": [{"name": "input"}],
  "input": {"shaft": "input", "speed_rpm": 1500}})";

class AnalyzeFile : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("analyze_file"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const diag::Recording& rec) const {
    const fs::path p = dir_ / name;
    diag::write_recording(p, rec);
    return p;
  }

  fs::path dir_;
};

TEST_F(AnalyzeFile, GivesWhatItsStepsGiveOneByOne) {
  diag::Recording rec = synthetic(40000, 1);
  rec.roles_stated = false;  // as measured files: the tacho is found by inference
  const fs::path file = write("run.h5", rec);
  const fs::path healthy = write("healthy.h5", synthetic(40000, 2));
  const diag::Gearbox gb = diag::parse_gearbox_text(kGearbox, "gb");

  detect::AnalyzeRequest q;
  q.recording = file;
  q.gearbox = gb;
  q.channels.tachos = {"key=input"};
  q.channels.rpm = 1510;
  q.baseline = {detect::RecordingInput(healthy)};
  q.options.threads = 1;
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_EQ(a.format, "hdf5");
  EXPECT_FALSE(a.cut);
  EXPECT_EQ(a.source, file.string());

  // The same, step by step.
  diag::Recording r = diag::open_recording(file);
  std::vector<std::string> notes;
  const diag::Gearbox at = diag::gearbox_at_speed(gb, r, q.channels, notes);
  for (std::string& n : diag::prepare_channels(r, &at, q.channels)) notes.push_back(n);
  diag::Recording h = diag::open_recording(healthy);
  diag::prepare_channels(h, &at, q.channels);
  detect::AnalyzeOptions o;
  o.threads = 1;
  detect::AnalysisResult expected = detect::analyze_recording(r, &at, o);
  expected.notes.insert(expected.notes.begin(), notes.begin(), notes.end());
  const std::vector<diag::Recording> hs = {h};
  const std::vector<std::string> names = {healthy.string()};
  expected.baseline = detect::score_against_baseline(r, hs, {}, names);
  detect::wear_against_baseline(expected, r, at, hs, o, names);

  // One frame: the whole record, every sample examined, its verdict and score in its segment.
  ASSERT_EQ(a.result.segments.size(), 1u);
  const detect::AnalysisSegment& seg = a.result.segments[0];
  EXPECT_EQ(seg.start_s, 0);
  EXPECT_EQ(seg.end_s, expected.duration_s);
  EXPECT_EQ(seg.verdict, expected.findings.empty() ? "no finding" : "finding");
  EXPECT_EQ(seg.anomaly_score, expected.baseline->anomaly_score);
  ASSERT_TRUE(a.result.coverage);
  EXPECT_TRUE(a.result.coverage->complete());
  EXPECT_EQ(a.result.coverage->analysed_s, expected.duration_s);
  expected.segments = a.result.segments;
  expected.coverage = a.result.coverage;
  ASSERT_EQ(a.result.findings.size(), expected.findings.size());
  for (std::size_t i = 0; i < expected.findings.size(); ++i) {
    EXPECT_EQ(a.result.findings[i].first_s, 0);
    EXPECT_EQ(a.result.findings[i].last_s, expected.duration_s);
    expected.findings[i].first_s = 0;
    expected.findings[i].last_s = expected.duration_s;
    expected.findings[i].frames_seen = expected.findings[i].frames_examined = 1;
  }
  EXPECT_EQ(report::to_json(a.result).dump(), report::to_json(expected).dump());
  // The speed note and the tacho are in the report: nothing of the setup is dropped.
  ASSERT_FALSE(a.result.notes.empty());
  EXPECT_NE(a.result.notes.front().find("1510 rpm from --rpm"), std::string::npos);
  EXPECT_EQ(a.result.speed.source, "tacho");
  ASSERT_TRUE(a.result.baseline.has_value());

  // A recording given in memory is the same analysis as its file.
  detect::AnalyzeRequest m = q;
  m.recording = detect::RecordingInput(std::make_shared<const diag::Recording>(rec), file);
  const detect::FileAnalysis b = detect::analyze_file(m);
  EXPECT_EQ(b.format, "memory");
  EXPECT_EQ(report::to_json(b.result).dump(), report::to_json(a.result).dump());
}

TEST_F(AnalyzeFile, ALongRecordingIsAnalysedFrameByFrameWithTheIndicatorsOverEverySample) {
  const fs::path file = write("long.h5", synthetic(120000, 3));
  detect::AnalyzeRequest q;
  q.recording = file;
  // Frames of at most 30 000 samples per channel (acc and the key: no channel over the frame
  // limit, ReadLimits), 3.75 s of 15 s: four frames.
  q.frame_samples = 30000;
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_FALSE(a.cut);
  ASSERT_TRUE(a.result.coverage);
  EXPECT_EQ(a.result.coverage->frames, 4u);
  EXPECT_TRUE(a.result.coverage->complete());
  EXPECT_EQ(a.result.duration_s, 15.0);
  ASSERT_EQ(a.result.segments.size(), 4u);
  EXPECT_EQ(a.result.segments[3].end_s, 15.0);
  ASSERT_EQ(a.result.channels.size(), 2u);          // acc and the key (no gearbox: a signal)
  EXPECT_EQ(a.result.channels[0].samples, 30000u);  // the detail frame's
  // One frame holding everything: the same time indicators (one-pass moments merged over the
  // frames: round-off only).
  q.frame_samples = 1u << 20;
  const detect::FileAnalysis w = detect::analyze_file(q);
  ASSERT_EQ(w.result.segments.size(), 1u);
  EXPECT_EQ(w.result.channels[0].samples, 120000u);
  for (auto field : {&detect::TimeIndicators::rms, &detect::TimeIndicators::kurtosis,
                     &detect::TimeIndicators::skewness, &detect::TimeIndicators::peak}) {
    EXPECT_NEAR(a.result.channels[0].time.*field, w.result.channels[0].time.*field,
                1e-12 * std::abs(w.result.channels[0].time.*field) + 1e-15);
  }
  // max_samples: an opt-in limit, the rest not examined.
  q.frame_samples = 30000;
  q.max_samples = 30000;
  const detect::FileAnalysis c = detect::analyze_file(q);
  EXPECT_TRUE(c.cut);
  EXPECT_FALSE(c.result.coverage->complete());
  EXPECT_EQ(c.result.coverage->frames, 1u);
  // Up to the first sample not examined (within one sample of 3.75 s).
  EXPECT_NEAR(c.result.coverage->analysed_s, 3.75, 1 / 8000.0);
}

// A tacho that drops out for a second: the frame that holds the silence is not examined (the
// kinematics would fill it with guessed revolutions), the reason names the tacho and the time; the
// other frames are analysed from the tacho.
TEST_F(AnalyzeFile, AFrameWhoseTachoDropsOutIsNotExamined) {
  diag::Recording rec = synthetic(120000, 5);                                 // 15 s
  for (std::size_t i = 40000; i < 48000; ++i) rec.signals[1].samples[i] = 0;  // 5-6 s: silent
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(std::make_shared<const diag::Recording>(rec), "dropout");
  q.gearbox = diag::parse_gearbox_text(kGearbox, "gb");
  q.channels.tachos = {"key=input"};
  q.frame_samples = 30000;  // four frames of 3.75 s
  q.options.traces = false;
  const detect::FileAnalysis a = detect::analyze_file(q);
  const detect::AnalysisResult& r = a.result;
  ASSERT_EQ(r.segments.size(), 4u);
  EXPECT_EQ(r.segments[1].verdict, "not examined");
  // The last pulse before the silence is at 4.96 s (less half a sample: the ideal edge's
  // crossing, tacho.hpp), the next at 6.0 s.
  EXPECT_NE(r.segments[1].reason.find("tacho 'key' drops out for 1.04 s from 4.9599"),
            std::string::npos)
      << r.segments[1].reason;
  for (std::size_t k : {0u, 2u, 3u}) {
    EXPECT_NE(r.segments[k].verdict, "not examined") << k << ": " << r.segments[k].reason;
    EXPECT_EQ(r.segments[k].speed_source, "tacho") << k;
  }
  EXPECT_FALSE(r.coverage->complete());
  EXPECT_EQ(r.coverage->frames_examined, 3u);
}

TEST_F(AnalyzeFile, ErrorsNameTheFileAtFault) {
  const fs::path file = write("run.h5", synthetic(20000, 4));
  const fs::path missing = dir_ / "missing.h5";
  auto message = [](const detect::AnalyzeRequest& q) {
    try {
      detect::analyze_file(q);
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  detect::AnalyzeRequest q;
  q.recording = missing;
  EXPECT_EQ(message(q), missing.string() + ": no such file");
  q.recording = file;
  q.baseline = {detect::RecordingInput(missing)};
  EXPECT_EQ(message(q), "--baseline " + missing.string() + ": no such file");
  q.baseline.clear();
  q.gear_baseline = detect::RecordingInput(missing);
  EXPECT_EQ(message(q), "--gear-baseline " + missing.string() + ": no such file");
  q.gear_baseline.reset();
  q.channels.rpm = 1000;  // a speed needs a description
  EXPECT_NE(message(q).find("--rpm: needs a gearbox description"), std::string::npos);
}

TEST_F(AnalyzeFile, ABaselineThatCannotScoreIsAnErrorOrKeptBesideTheAnalysis) {
  const fs::path file = write("run.h5", synthetic(20000, 5));
  const fs::path other_rate = write("other.h5", synthetic(20000, 6, 2 * kFs));
  detect::AnalyzeRequest q;
  q.recording = file;
  q.baseline = {detect::RecordingInput(other_rate)};
  EXPECT_THROW(detect::analyze_file(q), diag::InputError);
  q.baseline_required = false;  // a table's row: the analysis is kept, the reason beside it
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_NE(a.baseline_error.find("differs from the recording's"), std::string::npos)
      << a.baseline_error;
  EXPECT_EQ(a.result.channels.size(), 2u);
}

}  // namespace

namespace {

// A framed log's Welch PSD is the average over every frame's segments: white noise of variance 1
// in the first 2 s and 4 in the last 2 s, in 4 frames of 1 s (no description: time domain
// throughout). The one-sided density of white noise is 2 sigma^2 / fs: the log's mean density
// over the inner bins is 2 x its realized variance / fs (Parseval: the segments' Hann-weighted
// energy; within 1 %, measured 0.13 %), where the detail frame's alone would be a quarter or
// 1.6 times that. The segment count is the JSON's with or without the plot.
TEST(AnalyzeFilePsd, AFramedLogsPsdIsTheAverageOverEveryFrame) {
  constexpr double fs = 4096;
  auto rec = std::make_shared<diag::Recording>();
  diag::Signal s;
  s.name = "acc";
  s.fs_hz = fs;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  double sum_sq = 0;  // the realized variance (the mean is 0)
  for (std::size_t i = 0; i < 4 * 4096; ++i) {
    s.samples.push_back((i < 2 * 4096 ? 1.0 : 2.0) * g(rng));
    sum_sq += s.samples.back() * s.samples.back();
  }
  const double variance = sum_sq / static_cast<double>(s.samples.size());
  rec->signals.push_back(std::move(s));
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(rec, "noise");
  q.frame_s = 1.0;
  q.options.welch_nperseg = 256;
  q.options.plot_points = 100000;  // no decimation: every bin
  q.options.threads = 1;
  const detect::AnalysisResult r = detect::analyze_file(q).result;
  ASSERT_EQ(r.segments.size(), 4u);
  const detect::ChannelAnalysis& c = r.channels.at(0);
  EXPECT_EQ(c.psd_segments, 4u * 31u);  // (4096 - 256) / 128 + 1 per frame
  ASSERT_EQ(c.psd.y.size(), 129u);
  double mean = 0;
  for (std::size_t b = 1; b + 1 < c.psd.y.size(); ++b) mean += c.psd.y[b];
  mean /= static_cast<double>(c.psd.y.size() - 2);
  // The draw: sqrt(2 / 16384) x 4 / 2.5 = 1.8 % RMS (this seed: 2.9 % low).
  EXPECT_NEAR(variance / 2.5, 1.0, 0.05);
  EXPECT_NEAR(mean / (2 * variance / fs), 1.0, 0.01);

  q.options.traces = false;
  const detect::AnalysisResult bare = detect::analyze_file(q).result;
  EXPECT_EQ(bare.channels.at(0).psd_segments, c.psd_segments);
  EXPECT_TRUE(bare.channels.at(0).psd.y.empty());
}

}  // namespace
