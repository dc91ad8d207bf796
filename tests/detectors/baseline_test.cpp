// Baseline features, robust baseline and anomaly score on synthetic signals (no data needed).
#include "detect/baseline/baseline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <vector>

#include "diag/error.hpp"

namespace {

constexpr double kFsHz = 10000.0;
constexpr std::size_t kSamples = 1 << 17;

diag::Signal make_signal(std::vector<double> x, double fs_hz = kFsHz) {
  diag::Signal s;
  s.name = "x";
  s.fs_hz = fs_hz;
  s.samples = std::move(x);
  return s;
}

std::vector<double> gaussian_noise(unsigned seed, std::size_t n = kSamples, double sigma = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

// Impacts every `period` samples ringing a resonance at fr_hz (damping ratio 5 %): the shape of a
// localised gear or bearing fault.
void add_impacts(std::vector<double>& x, std::size_t period, double amplitude, double fr_hz) {
  const double wn = 2 * std::numbers::pi * fr_hz, zeta = 0.05;
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  const std::size_t ring = 400;
  for (std::size_t s = period / 2; s + ring < x.size(); s += period)
    for (std::size_t j = 0; j < ring; ++j) {
      const double t = static_cast<double>(j) / kFsHz;
      x[s + j] += amplitude * std::exp(-zeta * wn * t) * std::sin(wd * t);
    }
}

}  // namespace

// White noise has a flat PSD, so the expected share of a band is its share of the Welch bins. A
// band's energy sums n_b bins, each the mean of K periodograms (K = 2 N / nperseg - 1 Hann
// segments at 50 % overlap): relative scatter about 1 / sqrt(K n_b) (overlap and the Hann
// window's correlation of neighbouring bins raise it by less than 2x; 5 of these covers it).
TEST(BaselineFeatures, OfWhiteNoiseMatchBandWidthsGaussianKurtosisAndAFlatSpectrum) {
  const detect::BaselineFeatureOptions opt;
  const auto f = detect::baseline_features(make_signal(gaussian_noise(1)), opt);
  ASSERT_EQ(f.size(), 3u + opt.bands + 1u);

  const double segments = 2.0 * kSamples / opt.nperseg - 1;
  const double f_lo = opt.lowest_band_fraction;  // as a fraction of fs
  std::vector<int> bins(opt.bands, 0);
  int total = 0;
  for (std::size_t k = 0; k <= opt.nperseg / 2; ++k) {
    const double fk = static_cast<double>(k) / opt.nperseg;
    if (fk < f_lo) continue;
    const int b = std::min(opt.bands - 1,
                           int(std::floor(opt.bands * std::log(fk / f_lo) / std::log(0.5 / f_lo))));
    ++bins[b];
    ++total;
  }
  for (int b = 0; b < opt.bands; ++b) {
    SCOPED_TRACE(b);
    // 5 standard deviations of the band's log share (relative scatter of its energy)
    const double tol = 5.0 / std::sqrt(segments * bins[b]);
    EXPECT_NEAR(f.at("band" + std::to_string(b) + "_log_fraction"),
                std::log(double(bins[b]) / total), tol);
  }
  // Octave bands from fs/256 with 1024-point segments: 4, 8, ... 256 bins (+1 for Nyquist).
  EXPECT_EQ(bins[0], 4);
  EXPECT_EQ(bins[6], 257);

  // Sample kurtosis of N Gaussian samples: 3 with standard deviation sqrt(24 / N) = 0.0135,
  // 0.45 % of 3; 5 sigma in ln K.
  const double kLogKurtosisTol = 5 * std::sqrt(24.0 / kSamples) / 3.0;
  EXPECT_NEAR(f.at("kurtosis_log"), std::log(3.0), kLogKurtosisTol);
  // Skewness: standard deviation sqrt(6 / N) = 0.0068; 5 sigma.
  EXPECT_NEAR(f.at("skewness"), 0.0, 5 * std::sqrt(6.0 / kSamples));
  // Each averaged bin is chi-square with about 2 K dof scaled by its mean: E ln = -1/(2K) and
  // scatter 1/sqrt(K) per bin, averaged over ~500 bins: |flatness| well below 0.01.
  constexpr double kFlatnessTol = 0.01;
  EXPECT_NEAR(f.at("flatness_log"), 0.0, kFlatnessTol);
  // The largest of 131072 Gaussian samples sits near sqrt(2 ln N) = 4.8 sigma; crest in [4, 6].
  EXPECT_GT(f.at("crest_log"), std::log(4.0));
  EXPECT_LT(f.at("crest_log"), std::log(6.0));
}

TEST(BaselineFeatures, OfASineGiveItsKurtosisCrestAndAPeakedSpectrum) {
  std::vector<double> x(kSamples);
  // 500 Hz = fs/20: every period holds its peak sample (crest exactly sqrt 2 of the sampled
  // sine); 51.2 Welch bins, off-bin; octave band 3 of fs/256 * 2^i (312.5..625 Hz) holds it.
  for (std::size_t j = 0; j < x.size(); ++j)
    x[j] = 3.0 * std::sin(2 * std::numbers::pi * 500.0 * static_cast<double>(j) / kFsHz);
  const auto f = detect::baseline_features(make_signal(x));
  constexpr double kMomentTol = 1e-3;  // a record of non-whole periods: end effects O(1/cycles)
  EXPECT_NEAR(f.at("kurtosis_log"), std::log(1.5), kMomentTol);
  EXPECT_NEAR(f.at("crest_log"), std::log(std::sqrt(2.0)), kMomentTol);
  EXPECT_NEAR(f.at("skewness"), 0.0, kMomentTol);
  // Hann leakage puts < 1e-6 of a tone's energy more than a few bins away: band 4 holds ~all.
  EXPECT_NEAR(f.at("band3_log_fraction"), 0.0, 1e-6);
  EXPECT_LT(f.at("flatness_log"), -5.0);  // a line spectrum is anything but flat
  // Unit-free: the same sine at another gain and another (nominal) rate gives the same features.
  for (double& v : x) v *= 0.01;
  const auto g = detect::baseline_features(make_signal(x, 1.0));
  for (const auto& [name, value] : f) EXPECT_NEAR(g.at(name), value, 1e-9) << name;
}

// Median {1,2,3,4,100} = 3, |x - 3| = {2,1,0,1,97}, MAD = 1: spread 1.4826; a point at
// 3 + 2 * 1.4826 is 2 robust sigmas out, whatever the outlier 100 does.
TEST(Baseline, FitsMedianAndMadByHandAndScoresInRobustSigmas) {
  std::vector<detect::FeatureSet> healthy;
  for (double v : {1.0, 2.0, 100.0, 3.0, 4.0}) healthy.push_back({{"a", v}, {"b", 7.0}});
  detect::BaselineOptions opt;
  opt.spread_floor = 0.5;
  const auto b = detect::Baseline::fit(healthy, opt);
  constexpr double kExact = 1e-12;
  EXPECT_NEAR(b.features().at("a").centre, 3.0, kExact);
  EXPECT_NEAR(b.features().at("a").spread, 1.482602218505602, kExact);
  EXPECT_NEAR(b.features().at("b").centre, 7.0, kExact);
  EXPECT_EQ(b.features().at("b").spread, 0.5);  // constant feature: the floor

  const auto s = b.score({{"a", 3.0 + 2 * 1.482602218505602}, {"b", 6.0}, {"extra", 1e9}});
  EXPECT_NEAR(s.deviation.at("a"), 2.0, kExact);
  EXPECT_NEAR(s.deviation.at("b"), -2.0, kExact);
  EXPECT_EQ(s.deviation.count("extra"), 0u);
  EXPECT_NEAR(s.anomaly_score, 4.0, kExact);  // (4 + 4) / 2
  EXPECT_FALSE(s.alarm);
  EXPECT_EQ(s.threshold, 25.0);

  const auto back = detect::Baseline::from_json(b.to_json());
  EXPECT_EQ(back.score({{"a", 10.0}, {"b", 9.0}}).anomaly_score,
            b.score({{"a", 10.0}, {"b", 9.0}}).anomaly_score);
}

// Baseline of Gaussian noise records: another noise record does not alarm; the same noise with
// impacts ringing a resonance (peak impact 8 noise sigmas, one per 500 samples) does.
TEST(Baseline, OfGaussianNoiseAlarmsOnImpulsiveButNotOnFreshNoise) {
  constexpr std::size_t kRecord = 1 << 14;  // 16 segments' worth of features per record
  std::vector<detect::FeatureSet> healthy;
  for (unsigned seed = 10; seed < 30; ++seed)
    healthy.push_back(detect::baseline_features(make_signal(gaussian_noise(seed, kRecord))));
  const auto b = detect::Baseline::fit(healthy);

  for (unsigned seed = 100; seed < 105; ++seed) {
    const auto s = b.score(detect::baseline_features(make_signal(gaussian_noise(seed, kRecord))));
    EXPECT_FALSE(s.alarm) << "seed " << seed << " score " << s.anomaly_score;
    // Fresh noise: mean z^2 of 12 features near 1 (chi2_12 / 12 exceeds 3 with p = 2e-4).
    EXPECT_LT(s.anomaly_score, 3.0);
  }
  auto x = gaussian_noise(100, kRecord);
  add_impacts(x, 500, 8.0, 3000.0);
  const auto s = b.score(detect::baseline_features(make_signal(x)));
  EXPECT_TRUE(s.alarm) << "score " << s.anomaly_score << " largest " << s.largest;
}

TEST(Baseline, RejectsBadInputNamingTheField) {
  EXPECT_THROW(detect::Baseline::fit({{{"a", 1.0}}, {{"a", 2.0}}}), diag::InputError);  // < 3
  EXPECT_THROW(detect::Baseline::fit({{{"a", 1.0}}, {{"a", 2.0}}, {{"b", 2.0}}}),
               diag::InputError);  // names differ
  EXPECT_THROW(detect::Baseline::fit({{{"a", 1.0}}, {{"a", 2.0}}, {{"a", NAN}}}), diag::InputError);
  const auto b = detect::Baseline::fit({{{"a", 1.0}}, {{"a", 2.0}}, {{"a", 3.0}}});
  EXPECT_THROW(b.score({{"b", 1.0}}), diag::InputError);
  detect::BaselineOptions opt;
  opt.alarm_threshold = 0;
  EXPECT_THROW(opt.validate(), diag::InputError);
  detect::BaselineFeatureOptions fo;
  fo.bands = 0;
  EXPECT_THROW(detect::baseline_features(make_signal(gaussian_noise(1)), fo), diag::InputError);
  EXPECT_THROW(detect::baseline_features(make_signal(gaussian_noise(1, 1000))), diag::InputError);
  EXPECT_THROW(detect::baseline_features(make_signal(std::vector<double>(8192, 1.0))),
               diag::InputError);
  try {
    detect::Baseline::from_json(nlohmann::json{{"options", 1}});
    FAIL() << "no throw";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Baseline::from_json"), std::string::npos);
  }
}
