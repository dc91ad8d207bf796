// Streaming analysis of a recording on disk: a channel written in one go and read back in blocks
// of any size gives the one-shot detect::welch and detect::moments of the in-memory samples.
#include "detect/analysis/streaming.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"

namespace {

namespace fs = std::filesystem;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

class Streaming : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("streaming"); }
  void TearDown() override { fs::remove_all(dir_); }

  // Two channels: a decoy first, then "accel": a 1234.5 Hz tone of amplitude 2 on an offset of
  // 0.7 plus Gaussian noise (sigma 0.3), at 25.6 kHz; the length is no multiple of any block or
  // segment size used below, so partial blocks and a partial last segment occur.
  fs::path write(std::vector<double>& accel, std::size_t n = 300'007) {
    std::mt19937_64 rng(42);
    std::normal_distribution<double> g(0.0, 0.3);
    accel.resize(n);
    std::vector<double> decoy(n);
    for (std::size_t i = 0; i < n; ++i) {
      accel[i] = 0.7 + 2.0 * std::sin(kTwoPi * 1234.5 * i / kFs) + g(rng);
      decoy[i] = g(rng);
    }
    diag::Recording rec;
    for (auto [name, location, x] : {std::tuple{"decoy", "b1", &decoy}, {"accel", "b2", &accel}}) {
      diag::Signal& s = rec.signals.emplace_back();
      s.name = name;
      s.fs_hz = kFs;
      s.unit = "m/s^2";
      s.direction = diag::Direction::kVertical;
      s.location = location;
      s.samples = *x;
    }
    diag::Hdf5WriteOptions w;
    w.chunk_samples = 4096;  // file chunks smaller than most read blocks, unaligned with them
    const fs::path path = dir_ / "rec.h5";
    diag::write_recording(path, rec, w);
    return path;
  }

  static constexpr double kFs = 25600.0;
  fs::path dir_;
};

detect::StreamingOptions options(std::size_t block) {
  detect::StreamingOptions o;
  o.welch.nperseg = 2048;
  o.welch.fs_hz = 1.0;  // ignored: the channel's 25.6 kHz is used
  o.block_samples = block;
  return o;
}

TEST_F(Streaming, BlockwiseAnalysisOfAFileEqualsTheOneShotFunctions) {
  std::vector<double> x;
  const fs::path path = write(x);
  detect::WelchOptions w = options(1).welch;
  w.fs_hz = kFs;
  const detect::Psd psd_ref = detect::welch(x, w);
  const detect::Moments m_ref = detect::moments(x);

  // The moments are merged per block (Pebay) instead of two passes over everything: round-off
  // only. The reference itself sums N = 3e5 terms, a random walk of about sqrt(N) eps = 6e-14
  // relative (eps = 1.1e-16), so 1e-12 relative on the central sums (15 of those) and, for the
  // mean (terms up to |x| ~ 4: sqrt(N) eps 4 / 1 ~ 2.4e-13 absolute), 2e-12 absolute. The third
  // central sum is nearly zero (symmetric signal), so it is compared on the scale
  // m2^(3/2) / sqrt(N) of its own size (the skewness scale).
  constexpr double kSumRelTol = 1e-12;
  constexpr double kMeanAbsTol = 2e-12;
  diag::RecordingReader reader(path);
  for (std::size_t block :
       {std::size_t{1000}, std::size_t{2048}, std::size_t{65537}, std::size_t{1} << 20}) {
    SCOPED_TRACE("block_samples " + std::to_string(block));
    const detect::StreamingSummary s = detect::analyze_streaming(reader, "accel", options(block));
    EXPECT_EQ(s.channel, "signals/accel");
    EXPECT_EQ(s.samples, x.size());
    EXPECT_EQ(s.blocks, (x.size() + std::min(block, x.size()) - 1) / std::min(block, x.size()));
    EXPECT_DOUBLE_EQ(s.fs_hz, kFs);
    // WelchAccumulator promises the same bytes as welch() for any chunking.
    ASSERT_EQ(s.psd.value.size(), psd_ref.value.size());
    EXPECT_EQ(s.psd.segments, psd_ref.segments);
    for (std::size_t k = 0; k < psd_ref.value.size(); ++k) {
      ASSERT_EQ(s.psd.value[k], psd_ref.value[k]) << "bin " << k;
      ASSERT_EQ(s.psd.frequency_hz[k], psd_ref.frequency_hz[k]) << "bin " << k;
    }
    EXPECT_EQ(s.moments.count, m_ref.count);
    EXPECT_EQ(s.moments.min, m_ref.min);
    EXPECT_EQ(s.moments.max, m_ref.max);
    EXPECT_NEAR(s.moments.mean, m_ref.mean, kMeanAbsTol);
    EXPECT_NEAR(s.moments.m2, m_ref.m2, kSumRelTol * m_ref.m2);
    EXPECT_NEAR(s.moments.m4, m_ref.m4, kSumRelTol * m_ref.m4);
    const double m3_scale = std::pow(m_ref.m2, 1.5) / std::sqrt(static_cast<double>(x.size()));
    EXPECT_NEAR(s.moments.m3, m_ref.m3, kSumRelTol * m3_scale);
  }
}

TEST_F(Streaming, FindsTheToneAndTheSignalStatisticsOfTheFile) {
  // Independent of the one-shot functions: the tone's bin and the analytic moments.
  std::vector<double> x;
  const fs::path path = write(x);
  diag::RecordingReader reader(path);
  const detect::StreamingSummary s = detect::analyze_streaming(reader, "accel", options(5000));
  std::size_t peak = 1;
  for (std::size_t k = 1; k < s.psd.value.size(); ++k) {
    if (s.psd.value[k] > s.psd.value[peak]) peak = k;
  }
  // Bin spacing fs / nperseg = 12.5 Hz: the tone at 1234.5 Hz lies in bin 98.76 -> 99.
  EXPECT_EQ(peak, 99u);
  EXPECT_NEAR(s.psd.frequency_hz[peak], 99 * kFs / 2048, 1e-9);
  // Mean 0.7, variance A^2/2 + sigma^2 = 2.09, kurtosis (3 sigma^4 + 3 sigma^2 A^2 + 3 A^4 / 8) /
  // (A^2/2 + sigma^2)^2 = 1.6264 for A = 2, sigma = 0.3 (a sine plus weak noise is platykurtic).
  // Sampling spreads over 3e5 samples (checked over 40 seeds with numpy): mean 5.0e-4 (sigma /
  // sqrt(N)), variance 1.4e-3 (mostly the tone x noise cross term 2 A sigma / sqrt(2 N)),
  // kurtosis 1.0e-3; each tolerance is 5 to 7 of those spreads.
  constexpr double kMeanTol = 3e-3;
  constexpr double kVarianceTol = 1e-2;
  constexpr double kKurtosisTol = 6e-3;
  EXPECT_NEAR(s.moments.mean, 0.7, kMeanTol);
  EXPECT_NEAR(s.moments.variance(), 2.09, kVarianceTol);
  const double a2 = 4.0, s2 = 0.09;
  const double kurt =
      (3 * s2 * s2 + 3 * s2 * a2 + 3 * a2 * a2 / 8) / ((a2 / 2 + s2) * (a2 / 2 + s2));
  EXPECT_NEAR(s.moments.kurtosis(), kurt, kKurtosisTol);
}

TEST_F(Streaming, RefusesBadOptionsUnknownChannelsAndShortChannels) {
  std::vector<double> x;
  const fs::path path = write(x, 3000);
  diag::RecordingReader reader(path);
  EXPECT_THROW(detect::analyze_streaming(reader, "accel", options(0)), diag::InputError);
  EXPECT_THROW(detect::analyze_streaming(reader, "nope", options(1000)), diag::InputError);
  detect::StreamingOptions o = options(1000);
  o.welch.nperseg = 4096;  // longer than the 3000-sample channel
  try {
    detect::analyze_streaming(reader, "accel", o);
    FAIL() << "a channel shorter than nperseg was accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nperseg"), std::string::npos) << e.what();
  }
}

}  // namespace
