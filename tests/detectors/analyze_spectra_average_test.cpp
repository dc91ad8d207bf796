// A long log's amplitude and envelope spectra are the power average of its steady parts' (the
// frames of one layout), not the detail frame's alone: analyze_file on a synthetic record of
// four 2 s frames at 10 kHz, without a description, whose lines are known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "detect/analysis/analyze_file.hpp"

namespace {

constexpr double kFs = 10000.0;
constexpr double kFrameS = 2.0;
constexpr int kFrames = 4;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// A sine of amplitude 1 at 1 kHz throughout; one of amplitude 2 at 2.5 kHz in the last two frames
// only; impacts at 85 Hz ringing a 3.3 kHz resonance throughout (what the envelope demodulates);
// white noise of RMS 0.05.
std::shared_ptr<const diag::Recording> log_of_four_frames() {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  diag::Signal s;
  s.name = "accel";
  s.unit = "m/s^2";
  s.fs_hz = kFs;
  const auto n = static_cast<std::size_t>(kFrames * kFrameS * kFs);
  s.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kFs;
    // Impacts 85 times a second ringing a 3.3 kHz resonance (a bearing defect's signature).
    const double since = std::fmod(t, 1.0 / 85.0);
    double v = std::sin(kTwoPi * 1000.0 * t) +
               1.5 * std::exp(-since / 5e-4) * std::sin(kTwoPi * 3300.0 * since);
    if (t >= 2 * kFrameS) v += 2.0 * std::sin(kTwoPi * 2500.0 * t + 0.3);
    s.samples[i] = v + noise(rng);
  }
  auto rec = std::make_shared<diag::Recording>();
  rec->signals.push_back(std::move(s));
  return rec;
}

double peak_near(const std::vector<detect::SpectralPeak>& peaks, double hz) {
  for (const detect::SpectralPeak& p : peaks) {
    if (std::abs(p.frequency_hz - hz) < 2.0) return p.amplitude;
  }
  return 0.0;
}

// The 1 kHz line, in every frame, keeps its amplitude 1 in the average (1 %: the window's
// scalloping at these exact bins is nil, the noise adds under 0.1 %); the 2.5 kHz line, in two
// frames of four, averages in power to 2 / sqrt(2) = 1.414 (1 %), where the detail frame (the
// first: no finding anywhere) has no such line at all. The envelope spectra (each frame's in the
// band its kurtogram chose) are averaged over the four parts too. Traces or not, the peaks are
// the same; the part counts (the JSON's `parts`) say 4.
TEST(AnalyzeSpectraAverage, ALongLogsSpectraAreThePowerAverageOfItsParts) {
  for (const bool traces : {false, true}) {
    detect::AnalyzeRequest q;
    q.recording = detect::RecordingInput(log_of_four_frames(), "four frames");
    q.frame_s = kFrameS;
    q.options.traces = traces;
    const detect::AnalysisResult r = detect::analyze_file(q).result;
    ASSERT_TRUE(r.coverage);
    ASSERT_EQ(r.coverage->frames, 4u);
    ASSERT_EQ(r.channels.size(), 1u);
    const detect::ChannelAnalysis& c = r.channels[0];
    EXPECT_EQ(c.spectrum_parts, 4u) << traces;
    EXPECT_EQ(c.envelope_parts, 4u) << traces;
    EXPECT_NEAR(peak_near(c.spectrum_peaks, 1000.0), 1.0, 0.01) << traces;
    EXPECT_NEAR(peak_near(c.spectrum_peaks, 2500.0), 2.0 / std::sqrt(2.0), 0.014) << traces;
    EXPECT_FALSE(c.envelope_peaks.empty()) << traces;
    if (traces) {
      EXPECT_FALSE(c.spectrum.x.empty());
      EXPECT_FALSE(c.envelope.x.empty());
    }
  }
}

}  // namespace
