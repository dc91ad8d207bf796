// analyze on a long recording (AnalyzeOptions::whole_recording): the stages that need one record
// run on the first part (diag::ReadLimits), the time indicators and the Welch PSD are
// accumulated over the whole file block by block. A feature present only after the first part (a
// tone and a level rise in the second half) must show in them, and they must equal what the
// whole recording analysed in memory gives.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"
#include "report/report.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kFs = 10000.0;
constexpr std::size_t kLength = 83'001;  // no multiple of the 20 000-sample blocks
constexpr std::uint64_t kExcerpt = 20'000;
constexpr double kToneHz = 1000.0;

class WholeRecord : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* env = std::getenv("GEARDIAG_TMP");
    const fs::path base =
        env != nullptr && *env != '\0' ? fs::path(env) : fs::temp_directory_path();
    dir_ = base / ("whole_record_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    // Gaussian noise (sigma 0.5); from 4 s on, a 1 kHz tone of amplitude 3 on top: the first
    // 2 s (the excerpt) hold noise only.
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0.0, 0.5);
    diag::Recording rec;
    diag::Signal& s = rec.signals.emplace_back();
    s.name = "acc";
    s.fs_hz = kFs;
    s.unit = "m/s^2";
    s.samples.resize(kLength);
    for (std::size_t i = 0; i < kLength; ++i) {
      const double t = static_cast<double>(i) / kFs;
      s.samples[i] = g(rng) + (t >= 4.0 ? 3.0 * std::sin(2 * std::numbers::pi * kToneHz * t) : 0);
    }
    file_ = dir_ / "long.h5";
    diag::write_recording(file_, rec);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static double psd_at(const detect::ChannelAnalysis& c, double hz) {
    double best = 0;
    for (std::size_t k = 0; k < c.psd.x.size(); ++k) {
      if (std::abs(c.psd.x[k] - hz) < 5.0) best = std::max(best, c.psd.y[k]);
    }
    return best;
  }

  fs::path dir_, file_;
};

TEST_F(WholeRecord, IndicatorsAndPsdCoverTheWholeFile) {
  diag::ReadLimits limits;
  limits.max_samples = limits.kept_channel_samples = limits.max_channel_samples = kExcerpt;
  bool cut = false;
  const diag::Recording excerpt = diag::read_recording(file_, limits, &cut);
  ASSERT_TRUE(cut);
  ASSERT_EQ(excerpt.signals[0].samples.size(), kExcerpt);
  detect::AnalyzeOptions opt;
  const detect::AnalysisResult first = detect::analyze_recording(excerpt, nullptr, opt);
  opt.whole_recording = file_;
  const detect::AnalysisResult streamed = detect::analyze_recording(excerpt, nullptr, opt);
  const detect::AnalysisResult whole =
      detect::analyze_recording(diag::read_recording(file_), nullptr, {});
  const detect::ChannelAnalysis &f = first.channels[0], &s = streamed.channels[0],
                                &w = whole.channels[0];

  // The late tone and level rise are seen: RMS sqrt(0.25 + 4.5 x 43/83) = 1.61 against 0.5 on
  // the first part alone, and the PSD at 1 kHz rises by orders of magnitude (noise only there on
  // the first part).
  EXPECT_NEAR(f.time.rms, 0.5, 0.02);
  EXPECT_NEAR(s.time.rms, std::sqrt(0.25 + 4.5 * (kLength - 40000.0) / kLength), 0.02);
  EXPECT_GT(psd_at(s, kToneHz), 100 * psd_at(f, kToneHz));
  // And they are what the whole recording in memory gives: the same samples through running
  // moments and the Welch accumulator instead of one pass; 1e-9 relative allows the summation
  // order's round-off (~1e-13 here) and nothing else.
  EXPECT_NEAR(s.time.rms, w.time.rms, 1e-9 * w.time.rms);
  EXPECT_EQ(s.time.peak, w.time.peak);
  EXPECT_NEAR(s.time.kurtosis, w.time.kurtosis, 1e-9 * w.time.kurtosis);
  EXPECT_NEAR(s.time.crest_factor, w.time.crest_factor, 1e-9 * w.time.crest_factor);
  EXPECT_EQ(s.psd_segments, w.psd_segments);
  EXPECT_GT(s.psd_segments, 4 * f.psd_segments);
  ASSERT_EQ(s.psd.y.size(), w.psd.y.size());
  for (std::size_t k = 0; k < w.psd.y.size(); ++k) {
    ASSERT_EQ(s.psd.x[k], w.psd.x[k]) << k;
    ASSERT_NEAR(s.psd.y[k], w.psd.y[k], 1e-9 * w.psd.y[k]) << s.psd.x[k] << " Hz";
  }
  // The stages that need one record stay the first part's, and the report says what covered
  // what.
  EXPECT_EQ(s.samples, kExcerpt);
  EXPECT_EQ(s.spectrum_peaks.size(), f.spectrum_peaks.size());
  EXPECT_EQ(s.envelope_low_hz, f.envelope_low_hz);
  EXPECT_EQ(s.envelope_high_hz, f.envelope_high_hz);
  bool noted = false;
  for (const std::string& n : streamed.notes) {
    noted |= n.find("whole recording read by blocks (8.3001 s, 1 channels)") != std::string::npos &&
             n.find("mean of 4 blocks of 20000 samples") != std::string::npos;
  }
  EXPECT_TRUE(noted);
  // Without the plot curves (AnalyzeOptions::traces) the report is the same bytes: the PSD's
  // segment count over the whole file is then set from the Welch layout, and the envelope
  // spectra are still averaged over the blocks.
  opt.traces = false;
  EXPECT_EQ(report::to_json(detect::analyze_recording(excerpt, nullptr, opt)).dump(),
            report::to_json(streamed).dump());
}

// A recording read whole is left as it is (the stage finds nothing beyond what is held).
TEST_F(WholeRecord, RecordReadWholeIsUnchanged) {
  const diag::Recording rec = diag::read_recording(file_);
  detect::AnalyzeOptions opt;
  const detect::AnalysisResult plain = detect::analyze_recording(rec, nullptr, opt);
  opt.whole_recording = file_;
  const detect::AnalysisResult same = detect::analyze_recording(rec, nullptr, opt);
  EXPECT_EQ(same.notes, plain.notes);
  EXPECT_EQ(same.channels[0].time.rms, plain.channels[0].time.rms);
  EXPECT_EQ(same.channels[0].psd.y, plain.channels[0].psd.y);
  EXPECT_EQ(same.channels[0].envelope.y, plain.channels[0].envelope.y);
}

}  // namespace
