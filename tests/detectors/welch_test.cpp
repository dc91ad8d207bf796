// Welch PSD (against scipy.signal.welch, Parseval, streaming == one-shot) and the spectrogram
// (its rows average to Welch).
#include "detect/spectral/welch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "detect/spectral/spectrogram.hpp"
#include "diag/error.hpp"

namespace {

using detect::Detrend;
using detect::PsdScaling;
using detect::WelchOptions;
using detect::WindowType;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// White Gaussian noise of standard deviation sigma plus a 1.3-amplitude sine and a drift.
std::vector<double> test_record(std::size_t n, double fs_hz, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / fs_hz;
    x[j] = g(rng) + 1.3 * std::sin(kTwoPi * 0.1237 * fs_hz * t) + 0.2 + 0.05 * t;
  }
  return x;
}

bool scipy_available() {
  const std::string cmd =
      std::string(GEARDIAG_PYTHON) + " -c \"import scipy.signal\" >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

std::string scipy_window(WindowType w) {
  switch (w) {
    case WindowType::kRectangular:
      return "boxcar";
    case WindowType::kHann:
      return "hann";
    case WindowType::kHamming:
      return "hamming";
    case WindowType::kBlackmanHarris:
      return "blackmanharris";
    case WindowType::kFlatTopMatlab:
      return "flattop";
    case WindowType::kFlatTop:
      break;  // not in scipy
  }
  return "";
}

// The same record through scipy.signal.welch for every option set; one Python start.
std::vector<std::vector<double>> scipy_welch(const std::vector<double>& x,
                                             const std::vector<WelchOptions>& cases) {
  const auto dir = geardiag_test::scratch_dir("welch");
  const auto xin = dir / "welch_x.f64", cin = dir / "welch_cases.txt",
             out = dir / "welch_scipy.f64", script = dir / "welch_scipy.py";
  std::ofstream(xin, std::ios::binary)
      .write(reinterpret_cast<const char*>(x.data()),
             static_cast<std::streamsize>(x.size() * sizeof(double)));
  {
    std::ofstream c(cin);
    c.precision(17);
    for (const auto& o : cases) {
      c << o.fs_hz << ' ' << o.nperseg << ' ' << o.overlap() << ' ' << o.fft_length() << ' '
        << scipy_window(o.window) << ' '
        << (o.detrend == Detrend::kNone       ? "none"
            : o.detrend == Detrend::kConstant ? "constant"
                                              : "linear")
        << ' ' << (o.scaling == PsdScaling::kDensity ? "density" : "spectrum") << '\n';
    }
  }
  std::ofstream(script) << R"(import sys, numpy as np, scipy.signal as s
x = np.fromfile(sys.argv[1], dtype='<f8')
out = []
for line in open(sys.argv[2]):
    fs, nperseg, noverlap, nfft, win, detrend, scaling = line.split()
    f, p = s.welch(x, fs=float(fs), window=win, nperseg=int(nperseg), noverlap=int(noverlap),
                   nfft=int(nfft), detrend=False if detrend == 'none' else detrend,
                   scaling=scaling)
    out.append(p)
np.concatenate(out).astype('<f8').tofile(sys.argv[3])
)";
  const std::string cmd = std::string(GEARDIAG_PYTHON) + " " + script.string() + " " +
                          xin.string() + " " + cin.string() + " " + out.string();
  if (std::system(cmd.c_str()) != 0) return {};
  std::ifstream in(out, std::ios::binary);
  std::vector<std::vector<double>> r;
  for (const auto& o : cases) {
    std::vector<double> p(o.fft_length() / 2 + 1);
    in.read(reinterpret_cast<char*>(p.data()), static_cast<std::streamsize>(p.size() * 8));
    r.push_back(std::move(p));
  }
  return in ? r : std::vector<std::vector<double>>{};
}

// scipy computes in a different order (per-segment scaling, pairwise mean, pocketfft) than
// this code (FFTW, running sum, scaling at the end). Each bin's DFT carries a round-off of a few
// eps log2(nfft) relative to the segment's norm, and the K-term sums a few eps K relative: about
// 1e-13 of the largest bin in all. kRelTol covers the bins near the peak, kAbsTol (relative to
// the largest bin) the bins far below it.
constexpr double kRelTol = 1e-9;
constexpr double kAbsTol = 1e-12;

TEST(Welch, MatchesScipyForDefaultsAndEveryOption) {
  if (!scipy_available()) GTEST_SKIP() << GEARDIAG_PYTHON << " has no scipy; comparison skipped";
  const double fs = 2500.0;
  const auto x = test_record(50'000, fs, 0.7, 11);
  std::vector<WelchOptions> cases;
  WelchOptions base;
  base.fs_hz = fs;
  cases.push_back(base);  // scipy defaults: hann, 256, 128, constant, density
  auto add = [&](auto edit) {
    WelchOptions o = base;
    edit(o);
    cases.push_back(o);
  };
  add([](WelchOptions& o) { o.nperseg = 1000; });  // not a power of two
  add([](WelchOptions& o) {
    o.nperseg = 777;
    o.noverlap = 0;
  });  // odd, no overlap
  add([](WelchOptions& o) {
    o.nperseg = 512;
    o.noverlap = 500;
  });  // heavy overlap
  add([](WelchOptions& o) {
    o.nperseg = 300;
    o.nfft = 1024;
  });  // zero padding
  add([](WelchOptions& o) {
    o.nperseg = 300;
    o.nfft = 301;
  });  // odd nfft
  add([](WelchOptions& o) { o.detrend = Detrend::kLinear; });
  add([](WelchOptions& o) { o.detrend = Detrend::kNone; });
  add([](WelchOptions& o) {
    o.scaling = PsdScaling::kSpectrum;
    o.nperseg = 4096;
  });
  add([](WelchOptions& o) { o.window = WindowType::kHamming; });
  add([](WelchOptions& o) { o.window = WindowType::kBlackmanHarris; });
  add([](WelchOptions& o) { o.window = WindowType::kFlatTopMatlab; });
  add([](WelchOptions& o) {
    o.window = WindowType::kRectangular;
    o.nperseg = 64;
  });
  const auto ref = scipy_welch(x, cases);
  ASSERT_EQ(ref.size(), cases.size()) << "running scipy failed";
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const auto psd = detect::welch(x, cases[c]);
    ASSERT_EQ(psd.value.size(), ref[c].size()) << "case " << c;
    const double peak = *std::max_element(ref[c].begin(), ref[c].end());
    for (std::size_t k = 0; k < ref[c].size(); ++k) {
      ASSERT_NEAR(psd.value[k], ref[c][k], kRelTol * ref[c][k] + kAbsTol * peak)
          << "case " << c << " bin " << k;
      ASSERT_DOUBLE_EQ(psd.frequency_hz[k], k * fs / cases[c].fft_length());
    }
  }
}

// Parseval, exactly: with density scaling sum_k P_k df is the mean over segments of
// sum (w y)^2 / sum w^2, y the detrended segment (computed naively here).
TEST(Welch, IntegralOfDensityIsTheWindowWeightedMeanSquare) {
  constexpr double kRoundOff = 1e-12;  // relative; sums of 10^5 positive terms
  const double fs = 1000.0;
  const auto x = test_record(100'000, fs, 1.0, 3);
  WelchOptions o;
  o.fs_hz = fs;
  o.nperseg = 1024;
  o.noverlap = 300;
  const auto psd = detect::welch(x, o);
  double integral = 0.0;
  for (double p : psd.value) integral += p * psd.resolution_hz;

  const auto w = detect::make_window(WindowType::kHann, 1024);
  double w2 = 0.0;
  for (double v : w) w2 += v * v;
  double expected = 0.0;
  std::size_t segments = 0;
  for (std::size_t s = 0; s + 1024 <= x.size(); s += 1024 - 300, ++segments) {
    double mean = 0.0;
    for (std::size_t j = 0; j < 1024; ++j) mean += x[s + j] / 1024.0;
    double acc = 0.0;
    for (std::size_t j = 0; j < 1024; ++j) acc += std::pow(w[j] * (x[s + j] - mean), 2);
    expected += acc / w2;
  }
  expected /= static_cast<double>(segments);
  EXPECT_EQ(psd.segments, segments);
  EXPECT_NEAR(integral, expected, kRoundOff * expected);
}

// Parseval, statistically: white noise of variance 4 integrates to 4. The estimate is a mean
// square over ~2^20 samples (Hann segments overlapping by half are nearly independent in
// power, Welch 1967 Table 1): relative standard deviation about sqrt(2 / 2^20) = 1.4e-3; the
// 1 % tolerance is 7 of those.
TEST(Welch, IntegralOfWhiteNoiseDensityIsItsVariance) {
  constexpr double kRelTol = 0.01;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 2.0);
  std::vector<double> x(1 << 20);
  for (double& v : x) v = g(rng);
  WelchOptions o;
  o.fs_hz = 48'000.0;
  o.nperseg = 2048;
  const auto psd = detect::welch(x, o);
  double integral = 0.0;
  for (double p : psd.value) integral += p * psd.resolution_hz;
  EXPECT_NEAR(integral, 4.0, kRelTol * 4.0);
  // And the level: flat at 2 sigma^2 / fs (one-sided) - checked on the average of the interior.
  double mean = 0.0;
  for (std::size_t k = 1; k + 1 < psd.value.size(); ++k) mean += psd.value[k];
  mean /= static_cast<double>(psd.value.size() - 2);
  EXPECT_NEAR(mean, 2.0 * 4.0 / o.fs_hz, kRelTol * 2.0 * 4.0 / o.fs_hz);
}

// 'spectrum' scaling: a bin-centred sine of amplitude A reads A^2 / 2 at its bin.
TEST(Welch, SpectrumScalingReadsHalfTheSquaredAmplitudeOfABinCentredSine) {
  constexpr double kRoundOff = 1e-12;
  const double fs = 4096.0, a = 3.0;
  std::vector<double> x(65536);
  for (std::size_t j = 0; j < x.size(); ++j) x[j] = a * std::sin(kTwoPi * 250.0 * j / fs + 0.3);
  WelchOptions o;
  o.fs_hz = fs;
  o.nperseg = 2048;  // 2 Hz bins: 250 Hz is bin 125
  o.scaling = PsdScaling::kSpectrum;
  const auto psd = detect::welch(x, o);
  EXPECT_NEAR(psd.value[125], a * a / 2.0, kRoundOff * a * a);
  EXPECT_NEAR(psd.enbw_hz, 1.5 * fs / 2048, 1e-12);  // Hann: 1.5 bins
}

// The streaming accumulator fed any chunking (empty chunks, single samples, chunks longer than a
// segment) produces the one-shot result bit for bit.
TEST(Welch, StreamingInAnyChunksEqualsOneShotBitForBit) {
  const double fs = 1000.0;
  const auto x = test_record(30'011, fs, 1.0, 9);
  for (long long overlap : {-1LL, 0LL, 700LL}) {
    for (auto detrend : {Detrend::kConstant, Detrend::kLinear, Detrend::kNone}) {
      WelchOptions o;
      o.fs_hz = fs;
      o.nperseg = 1000;
      o.noverlap = overlap;
      o.detrend = detrend;
      o.nfft = 1200;
      const auto one_shot = detect::welch(x, o);
      detect::WelchAccumulator acc(o);
      std::mt19937 rng(1);
      std::uniform_int_distribution<std::size_t> size(0, 2500);
      std::size_t pos = 0;
      while (pos < x.size()) {
        std::size_t c = std::min(size(rng) % 3 == 0 ? size(rng) % 3 : size(rng), x.size() - pos);
        acc.push(std::span<const double>(x).subspan(pos, c));
        pos += c;
      }
      EXPECT_EQ(acc.samples(), x.size());
      const auto streamed = acc.result();
      EXPECT_EQ(streamed.segments, one_shot.segments);
      EXPECT_EQ(streamed.value, one_shot.value) << "overlap " << overlap;
      acc.reset();
      acc.push(x);
      EXPECT_EQ(acc.result().value, one_shot.value);
    }
  }
}

TEST(Welch, SegmentCountIsScipys) {
  WelchOptions o;
  o.nperseg = 100;
  o.noverlap = 30;
  const std::vector<double> x(1000, 1.0);
  // K = floor((N - noverlap) / (nperseg - noverlap)) = floor(970 / 70) = 13.
  EXPECT_EQ(detect::welch(x, o).segments, 13u);
}

TEST(Welch, BadOptionsAndInputsAreNamedInTheError) {
  auto message = [](auto f) {
    try {
      f();
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::vector<double> x(1000, 1.0);
  WelchOptions o;
  o.nperseg = 0;
  EXPECT_EQ(message([&] { o.validate(); }), "welch: nperseg: 0 is not in [8, 2^24]");
  o.nperseg = 64;
  o.noverlap = 64;
  EXPECT_NE(message([&] { o.validate(); }).find("welch: noverlap: 64"), std::string::npos);
  o.noverlap = -1;
  o.nfft = 32;
  EXPECT_NE(message([&] { o.validate(); }).find("welch: nfft: 32"), std::string::npos);
  o.nfft = 0;
  o.fs_hz = -1;
  EXPECT_NE(message([&] { o.validate(); }).find("welch: fs_hz"), std::string::npos);
  o.fs_hz = 1;
  EXPECT_NE(message([&] { detect::welch({}, o); }).find("welch: x: 0 samples"), std::string::npos);
  const std::vector<double> one{1.0};
  EXPECT_NE(message([&] { detect::welch(one, o); }).find("fewer than nperseg"), std::string::npos);
  auto bad = x;
  bad[500] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message([&] { detect::welch(bad, o); }).find("non-finite"), std::string::npos);
  // A sample in no segment (the tail after the last whole one) is checked too.
  std::vector<double> tail(1050, 1.0);
  tail[1020] = std::numeric_limits<double>::infinity();
  o.nperseg = 100;
  o.noverlap = 0;
  EXPECT_EQ(message([&] { detect::welch(std::span(tail).first(1010), o); }), "no error");
  EXPECT_NE(message([&] { detect::welch(tail, o); }).find("welch: x: sample 1020 is not finite"),
            std::string::npos);
}

// ---- spectrogram ----

// Each PSD row is one Welch segment, so the rows' mean is the Welch PSD (same segments).
TEST(Spectrogram, RowsAverageToWelch) {
  constexpr double kRoundOff = 1e-12;  // relative to the largest bin
  const double fs = 1000.0;
  const auto x = test_record(20'000, fs, 1.0, 2);
  detect::SpectrogramOptions so;
  so.fs_hz = fs;
  so.nperseg = 500;
  so.noverlap = 100;
  const auto sg = detect::spectrogram(x, so);
  WelchOptions wo;
  wo.fs_hz = fs;
  wo.nperseg = 500;
  wo.noverlap = 100;
  const auto psd = detect::welch(x, wo);
  ASSERT_EQ(sg.time_s.size(), psd.segments);
  const double peak = *std::max_element(psd.value.begin(), psd.value.end());
  for (std::size_t k = 0; k < psd.value.size(); ++k) {
    double mean = 0.0;
    for (std::size_t m = 0; m < sg.time_s.size(); ++m) mean += sg.at(m, k);
    mean /= static_cast<double>(sg.time_s.size());
    EXPECT_NEAR(mean, psd.value[k], kRoundOff * peak) << k;
  }
  EXPECT_DOUBLE_EQ(sg.time_s[0], 250.0 / fs);  // centre of the first segment
  EXPECT_DOUBLE_EQ(sg.time_s[1], 650.0 / fs);  // step 400
}

// A tone that jumps from 100 Hz to 300 Hz half way: each segment's largest amplitude is the
// tone of its time, at its amplitude (bin-centred, so exact to round-off).
TEST(Spectrogram, FollowsATonesFrequencyAndAmplitudeInTime) {
  constexpr double kRoundOff = 1e-12;
  const double fs = 1024.0;
  std::vector<double> x(8192);
  for (std::size_t j = 0; j < x.size(); ++j)
    x[j] = j < 4096 ? 2.0 * std::sin(kTwoPi * 100.0 * j / fs)
                    : 0.5 * std::sin(kTwoPi * 300.0 * j / fs);
  detect::SpectrogramOptions so;
  so.fs_hz = fs;
  so.nperseg = 256;  // 4 Hz bins; segments at multiples of 128 samples never straddle 4096
  so.noverlap = 128;
  so.mode = detect::SpectrogramMode::kAmplitude;
  const auto sg = detect::spectrogram(x, so);
  for (std::size_t m = 0; m < sg.time_s.size(); ++m) {
    const std::size_t start = m * 128;
    if (start < 4096 && start + 256 > 4096) continue;  // the segment holding the jump
    const bool first = start + 256 <= 4096;
    const std::size_t bin = first ? 25 : 75;
    EXPECT_NEAR(sg.at(m, bin), first ? 2.0 : 0.5, kRoundOff) << m;
  }
  EXPECT_THROW(detect::spectrogram(std::vector<double>(100, 0.0), so), diag::InputError);
}

}  // namespace

namespace {

// WelchOptions::segments(n) is the count welch() averages, for every overlap and the lengths
// around a whole number of steps.
TEST(Welch, SegmentsIsTheCountWelchAverages) {
  std::vector<double> x(3000, 1.0);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.1 * static_cast<double>(i));
  for (long long noverlap : {-1LL, 0LL, 7LL, 63LL}) {
    detect::WelchOptions o;
    o.nperseg = 64;
    o.noverlap = noverlap;
    for (std::size_t n : {64u, 65u, 95u, 96u, 97u, 127u, 128u, 129u, 1000u, 3000u}) {
      EXPECT_EQ(o.segments(n), detect::welch(std::span<const double>(x).first(n), o).segments)
          << "noverlap " << noverlap << ", n " << n;
    }
    EXPECT_EQ(o.segments(63), 0u);
  }
}

}  // namespace
