#include "detect/indicators/indicators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "detect/indicators/na4.hpp"
#include "diag/error.hpp"

namespace {

using std::numbers::pi;

// Sums of a handful of doubles: round-off of a few ulps of the largest term.
constexpr double kRoundOff = 1e-12;

std::vector<double> gaussian(std::size_t n, std::uint64_t seed, double mean = 0, double sd = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(mean, sd);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

// A revolution of n samples of sum_i a_i cos(k_i theta + phi_i).
std::vector<double> orders(std::size_t n,
                           std::initializer_list<std::tuple<int, double, double>> t) {
  std::vector<double> x(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const double th = 2 * pi * static_cast<double>(j) / static_cast<double>(n);
    for (const auto& [k, a, ph] : t) x[j] += a * std::cos(k * th + ph);
  }
  return x;
}

// ---- Time-domain statistics on hand-computed signals -------------------------------------------

// x = {0, 0, 0, 0, 4}: mean 0.8, deviations -0.8 (x4) and 3.2.
//   sum d^2 = 4(0.64) + 10.24 = 12.8;  sum d^3 = 4(-0.512) + 32.768 = 30.72
//   sum d^4 = 4(0.4096) + 104.8576 = 106.496
//   sum d^6 = 4(0.262144) + 1073.741824 = 1074.7904
//   sum d^8 = 4(0.16777216) + 10995.11627776 = 10995.7873664
// kurtosis = 5 (106.496) / 12.8^2 = 3.25; skewness = sqrt(5) 30.72 / 12.8^1.5 = 1.5;
// M6A = 25 (1074.7904) / 12.8^3 = 12.8125; M8A = 125 (10995.7873664) / 12.8^4 = 51.203125;
// RMS = sqrt(16 / 5); peak 4; peak-to-peak 4; crest = 4 / sqrt(3.2) = sqrt(5).
TEST(Indicators, MatchHandComputedValuesOnASingleSpike) {
  const std::vector<double> x = {0, 0, 0, 0, 4};
  EXPECT_NEAR(detect::kurtosis(x), 3.25, kRoundOff);
  EXPECT_NEAR(detect::skewness(x), 1.5, kRoundOff);
  EXPECT_NEAR(detect::fm4(x), 3.25, kRoundOff);
  EXPECT_NEAR(detect::m6a(x), 12.8125, kRoundOff * 10);
  EXPECT_NEAR(detect::m8a(x), 51.203125, kRoundOff * 100);
  EXPECT_NEAR(detect::rms(x), std::sqrt(16.0 / 5.0), kRoundOff);
  EXPECT_DOUBLE_EQ(detect::peak(x), 4.0);
  EXPECT_DOUBLE_EQ(detect::peak_to_peak(x), 4.0);
  EXPECT_NEAR(detect::crest_factor(x), std::sqrt(5.0), kRoundOff);
  const detect::Moments m = detect::moments(x);
  EXPECT_EQ(m.count, 5u);
  EXPECT_NEAR(m.mean, 0.8, kRoundOff);
  EXPECT_NEAR(m.m2, 12.8, kRoundOff);
  EXPECT_NEAR(m.m3, 30.72, kRoundOff * 10);
  EXPECT_NEAR(m.m4, 106.496, kRoundOff * 100);
}

// A sine sampled over whole periods: the sample means of sin^2, sin^4, sin^6, sin^8 equal the
// continuous ones (1/2, 3/8, 5/16, 35/128) exactly when no harmonic 2k..8k of the k cycles aliases
// to DC (n = 1000, k = 7: 8k = 56 < n). Hence kurtosis (3/8)/(1/2)^2 = 3/2, M6A (5/16)/(1/8) = 5/2,
// M8A (35/128)/(1/16) = 35/8, crest factor sqrt(2), skewness 0, RMS A/sqrt(2).
TEST(Indicators, SineHasClosedFormMoments) {
  const double a = 2.5;
  const std::vector<double> x = orders(1000, {{7, a, 0.3}});
  EXPECT_NEAR(detect::kurtosis(x), 1.5, kRoundOff);
  EXPECT_NEAR(detect::m6a(x), 2.5, kRoundOff);
  EXPECT_NEAR(detect::m8a(x), 35.0 / 8.0, kRoundOff * 10);
  EXPECT_NEAR(detect::skewness(x), 0.0, kRoundOff);
  EXPECT_NEAR(detect::rms(x), a / std::sqrt(2.0), kRoundOff);
  // Sampling misses the crest by at most 1 - cos(pi k / n): 2.4e-4 relative for k/n = 7/1000.
  constexpr double kCrestSampling = 3e-4;
  EXPECT_NEAR(detect::crest_factor(x), std::sqrt(2.0), kCrestSampling * std::sqrt(2.0));
}

// Gaussian noise: E[x^4] = 3, E[x^6] = 15, E[x^8] = 105 sigma^p. Standard errors of the normalised
// sample moments at n samples (delta method with the moments of the normal distribution):
//   kurtosis sqrt(24 / n), skewness sqrt(6 / n),
//   M6A sqrt((E x^12 - 15^2 - 2 (45) (E x^8 - 15) + 45^2 Var x^2) / n) = sqrt(6120 / n),
//   M8A sqrt((E x^16 - 105^2 - 2 (420) (E x^10 - 105) + 420^2 2) / n) = sqrt(1663200 / n).
// Tolerance: 5 standard errors (the seed is fixed; 5 sigma keeps the test honest if it changes).
TEST(Indicators, GaussianNoiseHasKurtosisThree) {
  const std::size_t n = 1 << 20;
  const std::vector<double> x = gaussian(n, 42, 3.0, 0.7);
  const double nd = static_cast<double>(n);
  constexpr double kSigmas = 5.0;
  EXPECT_NEAR(detect::kurtosis(x), 3.0, kSigmas * std::sqrt(24.0 / nd));
  EXPECT_NEAR(detect::skewness(x), 0.0, kSigmas * std::sqrt(6.0 / nd));
  EXPECT_NEAR(detect::m6a(x), 15.0, kSigmas * std::sqrt(6120.0 / nd));
  EXPECT_NEAR(detect::m8a(x), 105.0, kSigmas * std::sqrt(1663200.0 / nd));
}

TEST(Indicators, RejectEmptySignalsAndReturnNaNForZeroVariance) {
  const std::vector<double> empty;
  EXPECT_THROW(detect::rms(empty), diag::InputError);
  EXPECT_THROW(detect::kurtosis(empty), diag::InputError);
  EXPECT_THROW(detect::m8a(empty), diag::InputError);
  const std::vector<double> flat(10, 2.0);
  EXPECT_TRUE(std::isnan(detect::kurtosis(flat)));
  EXPECT_TRUE(std::isnan(detect::m6a(flat)));
  EXPECT_DOUBLE_EQ(detect::crest_factor(flat), 1.0);
  const std::vector<double> zero(10, 0.0);
  EXPECT_TRUE(std::isnan(detect::crest_factor(zero)));
}

// ---- Streaming moments
// ----------------------------------------------------------------------------

// Chunked accumulation agrees with a long-double two-pass reference written here, whatever the
// chunk size, and so does the one-shot moments(); the data have a mean 1e6 times their spread,
// where naive power sums would lose every digit of the fourth moment.
// Tolerances: a double sum of n terms drifts by about sqrt(n) eps relative (random walk of
// rounding errors), so the mean is good to kMeanRel = 4 sqrt(n) eps. The central sums inherit
// the errors of the chunk means (up to sqrt(65536) eps 1e6 = 3e-8 absolute here) through the
// merge's cross terms: observed 5e-11 relative on m2 and m4 at mean/spread = 1e6; kRel = 1e-9
// allows 20 times that. m3 is also moved by -3 delta m2 by an error delta in the final mean,
// hence its bound 3 kMeanRel |mean| m2 + kRel sqrt(m2 m4).
TEST(MomentAccumulator, ChunkedEqualsTwoPassReferenceForAnyChunkSize) {
  const std::size_t n = 200003;  // prime: chunks never divide it evenly
  const std::vector<double> x = gaussian(n, 7, 1e6, 1.0);
  long double mean_l = 0;
  for (double v : x) mean_l += v;
  mean_l /= n;
  long double s2 = 0, s3 = 0, s4 = 0, sq = 0;
  for (double v : x) {
    const long double d = v - mean_l;
    s2 += d * d, s3 += d * d * d, s4 += d * d * d * d, sq += static_cast<long double>(v) * v;
  }
  const double mean = static_cast<double>(mean_l), m2 = static_cast<double>(s2),
               m3 = static_cast<double>(s3), m4 = static_cast<double>(s4);
  const double rms = static_cast<double>(std::sqrt(sq / n));
  const double kMeanRel = 4 * std::sqrt(static_cast<double>(n)) * 2.2e-16;
  constexpr double kRel = 1e-9;
  const double m3_tol = 3 * kMeanRel * mean * m2 + kRel * std::sqrt(m2 * m4);
  auto check = [&](const detect::Moments& m, const std::string& what) {
    EXPECT_EQ(m.count, n) << what;
    EXPECT_NEAR(m.mean, mean, kMeanRel * mean) << what;
    EXPECT_NEAR(m.m2, m2, kRel * m2) << what;
    EXPECT_NEAR(m.m3, m3, m3_tol) << what;
    EXPECT_NEAR(m.m4, m4, kRel * m4) << what;
    EXPECT_NEAR(m.kurtosis(), n * m4 / (m2 * m2), 3 * kRel) << what;
    EXPECT_NEAR(m.rms(), rms, kMeanRel * rms) << what;
    EXPECT_EQ(m.min, *std::min_element(x.begin(), x.end())) << what;
    EXPECT_EQ(m.max, *std::max_element(x.begin(), x.end())) << what;
  };
  check(detect::moments(x), "one-shot");
  for (std::size_t chunk :
       {std::size_t{1}, std::size_t{3}, std::size_t{1000}, std::size_t{65536}, n}) {
    detect::MomentAccumulator acc;
    for (std::size_t i = 0; i < n; i += chunk)
      acc.add(std::span<const double>(x).subspan(i, std::min(chunk, n - i)));
    check(acc.result(), "chunk " + std::to_string(chunk));
  }
}

TEST(MomentAccumulator, MergingTwoHalvesEqualsTheWhole) {
  const std::vector<double> x = gaussian(10000, 9, -2.0, 3.0);
  detect::MomentAccumulator a, b;
  a.add(std::span<const double>(x).first(3000));
  b.add(std::span<const double>(x).subspan(3000));
  a.merge(b);
  const detect::Moments ref = detect::moments(x);
  EXPECT_NEAR(a.result().m4, ref.m4, 1e-12 * ref.m4);
  EXPECT_NEAR(a.result().m3, ref.m3, 1e-12 * std::sqrt(ref.m2 * ref.m4));
  EXPECT_NEAR(a.result().crest_factor(), detect::crest_factor(x), kRoundOff);
  detect::MomentAccumulator empty;
  EXPECT_THROW(empty.result(), diag::InputError);
}

// ---- Gear metrics on synthetic revolutions
// -------------------------------------------------------

// A term A cos(k theta + phi) lands in order k with amplitude A, whatever the phase.
TEST(GearMetrics, OrderAmplitudesReadEachTermsAmplitude) {
  const auto x = orders(256, {{0, 0.5, 0.0}, {3, 1.25, 1.0}, {40, 0.2, -2.0}, {128, 0.1, 0.0}});
  const std::vector<double> a = detect::order_amplitudes(x);
  ASSERT_EQ(a.size(), 129u);
  EXPECT_NEAR(a[0], 0.5, kRoundOff);
  EXPECT_NEAR(a[3], 1.25, kRoundOff);
  EXPECT_NEAR(a[40], 0.2, kRoundOff);
  EXPECT_NEAR(a[128], 0.1, kRoundOff);  // Nyquist: cos(pi j) has no mirror bin
  EXPECT_NEAR(a[5], 0.0, kRoundOff);
}

// FM0 = PP / sum of mesh-harmonic amplitudes.
//  - a pure mesh tone A cos(z theta): PP = 2A, sum = A, FM0 = 2;
//  - cos(z theta) + 0.25 cos(2 z theta) = 0.5 c^2 + c - 0.25 with c = cos(z theta): max 1.25 at
//    c = 1, min -0.75 at c = -1 (the parabola's vertex is at c = -1), so PP = 2 and FM0 = 2/1.25 =
//    1.6 (both extremes are sampled: 256 samples, z = 8, so theta = 0 and pi/8 fall on samples);
//  - a shaft-order term adds to PP but not to the denominator.
TEST(GearMetrics, Fm0MatchesHandComputedValues) {
  detect::GearMetricOptions opt;
  opt.mesh_order = 8;
  opt.mesh_harmonics = 3;
  opt.ser_sidebands = 6;
  auto fm0_of = [&](const std::vector<double>& x) {
    return detect::fm0(x, detect::order_amplitudes(x), opt);
  };
  // Phase 0.4 rad with samples every pi/16 of mesh phase: the nearest samples sit 0.0073 rad from
  // the crest and the trough, so PP is short by 2 A (1 - cos 0.0073) = 5e-5 A.
  constexpr double kCrestSampling = 1e-4;
  EXPECT_NEAR(fm0_of(orders(256, {{8, 3.0, 0.4}})), 2.0, kCrestSampling);
  EXPECT_NEAR(fm0_of(orders(256, {{8, 1.0, 0.0}, {16, 0.25, 0.0}})), 1.6, kRoundOff);
  const double with_shaft = fm0_of(orders(256, {{8, 1.0, 0.0}, {1, 0.5, 0.0}}));
  EXPECT_GT(with_shaft, 2.0);
}

// SER, SLF, SI from a revolution holding the mesh order z = 20 with amplitude 1 and sidebands
// 0.1 (z-1), 0.2 (z+1), 0.05 (z+3), and 0.3 at z+7 (outside SER's six):
//   SER = (0.1 + 0.2 + 0.05) / 1 = 0.35;  SI = (0.1 + 0.2) / 2 = 0.15;
//   RMS = sqrt((1 + 0.01 + 0.04 + 0.0025 + 0.09) / 2) = sqrt(0.57125); SLF = 0.3 / RMS.
TEST(GearMetrics, SidebandMetricsMatchHandComputedValues) {
  const auto x = orders(
      512, {{20, 1.0, 0.0}, {19, 0.1, 0.5}, {21, 0.2, 1.5}, {23, 0.05, 2.0}, {27, 0.3, 0.0}});
  detect::GearMetricOptions opt;
  opt.mesh_order = 20;
  const auto a = detect::order_amplitudes(x);
  EXPECT_NEAR(detect::sideband_energy_ratio(a, opt), 0.35, kRoundOff);
  EXPECT_NEAR(detect::sideband_index(a, opt), 0.15, kRoundOff);
  EXPECT_NEAR(detect::sideband_level_factor(x, a, opt), 0.3 / std::sqrt(0.57125), kRoundOff);
}

// ER = RMS(d) / RMS(y): 0.5 sin(3 theta) over cos(20 theta) is 0.5 (RMS of a whole-period sine
// is its amplitude / sqrt(2)).
TEST(GearMetrics, EnergyRatioIsTheRmsRatio) {
  const auto d = orders(512, {{3, 0.5, -pi / 2}});
  const auto y = orders(512, {{20, 1.0, 0.0}});
  EXPECT_NEAR(detect::energy_ratio(d, y), 0.5, kRoundOff);
}

TEST(GearMetrics, OptionsNameTheFieldAtFault) {
  detect::GearMetricOptions opt;
  opt.mesh_order = 0;
  EXPECT_THROW(opt.validate(256), diag::InputError);
  opt.mesh_order = 5;  // SER's 6 lower sidebands would reach order -1
  try {
    opt.validate(256);
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ser_sidebands"), std::string::npos) << e.what();
  }
  opt.mesh_order = 50;  // 3rd harmonic at order 150 > 128
  try {
    opt.validate(256);
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh_order"), std::string::npos) << e.what();
  }
  opt.mesh_order = 40;  // 120 < 128: fine
  EXPECT_NO_THROW(opt.validate(256));
}

// ---- NA4
// ---------------------------------------------------------------------------------------------

// Records (population variance v, fourth central moment mu4):
//   r1 = {1,-1,1,-1}: v = 1, mu4 = 1;   r2 = {2,-2,2,-2}: v = 4, mu4 = 16;
//   r3 = {0,0,0,3}: mean 0.75, deviations -0.75 (x3), 2.25: v = (3 (0.5625) + 5.0625)/4 = 1.6875,
//   mu4 = (3 (0.31640625) + 25.62890625)/4 = 6.64453125.
// NA4 after each push: 1/1^2 = 1; 16/((1+4)/2)^2 = 2.56; 6.64453125/((1+4+1.6875)/3)^2.
TEST(Na4Ensemble, MatchesHandComputedRunValues) {
  detect::Na4Ensemble e;
  EXPECT_THROW(e.value(std::vector<double>{1.0}), diag::InputError);
  EXPECT_NEAR(e.push(std::vector<double>{1, -1, 1, -1}), 1.0, kRoundOff);
  EXPECT_NEAR(e.push(std::vector<double>{2, -2, 2, -2}), 2.56, kRoundOff);
  const std::vector<double> r3 = {0, 0, 0, 3};
  e.add(r3);
  const double mean_var = (1.0 + 4.0 + 1.6875) / 3.0;
  EXPECT_NEAR(e.mean_variance(), mean_var, kRoundOff);
  EXPECT_NEAR(e.value(r3), 6.64453125 / (mean_var * mean_var), kRoundOff);
  EXPECT_EQ(e.records(), 3u);
}

// The reason NA4 exists: once damage spreads, the residual's own kurtosis falls back towards 3
// while its variance grows; NA4, normalised by the run's average variance, keeps rising.
TEST(Na4Ensemble, KeepsRisingWhenDamageSpreadsWhileKurtosisFallsBack) {
  detect::Na4Ensemble e;
  for (int rec = 0; rec < 20; ++rec) e.add(gaussian(4096, 100 + rec));  // healthy run, v = 1
  const std::vector<double> spread = gaussian(4096, 999, 0.0, 3.0);     // distributed damage
  e.add(spread);
  const double na4 = e.value(spread);
  // kurtosis(spread) is ~3 (Gaussian, standard error sqrt(24/4096) = 0.08); NA4 = mu4/(mean v)^2
  // with mu4 = 3 * 81 and mean v = (20 + 9)/21: 243 / 1.907 = 127, far above.
  EXPECT_NEAR(detect::kurtosis(spread), 3.0, 5 * std::sqrt(24.0 / 4096));
  EXPECT_GT(na4, 100.0);
}

// gear_indicators gathers the same numbers as the individual functions and leaves metrics
// without their signal NaN.
TEST(GearMetrics, GearIndicatorsAgreesWithTheSingleMetrics) {
  const auto tsa = orders(512, {{20, 1.0, 0.0}, {19, 0.1, 0.5}, {21, 0.2, 1.5}, {1, 0.3, 0.0}});
  const auto regular = orders(512, {{20, 1.0, 0.0}, {1, 0.3, 0.0}});
  std::vector<double> diff = gaussian(512, 5, 0.0, 0.1);
  diff[100] += 1.0;
  const std::vector<double> residual = diff;
  detect::GearMetricOptions opt;
  opt.mesh_order = 20;
  detect::Na4Ensemble ens;
  ens.add(gaussian(512, 6, 0.0, 0.1));
  ens.add(residual);
  const detect::GearIndicators g =
      detect::gear_indicators({tsa, diff, regular, residual}, opt, &ens);
  const auto a = detect::order_amplitudes(tsa);
  EXPECT_DOUBLE_EQ(g.fm0, detect::fm0(tsa, a, opt));
  EXPECT_DOUBLE_EQ(g.fm4, detect::fm4(diff));
  EXPECT_DOUBLE_EQ(g.m6a, detect::m6a(diff));
  EXPECT_DOUBLE_EQ(g.m8a, detect::m8a(diff));
  EXPECT_DOUBLE_EQ(g.er, detect::energy_ratio(diff, regular));
  EXPECT_DOUBLE_EQ(g.ser, detect::sideband_energy_ratio(a, opt));
  EXPECT_DOUBLE_EQ(g.slf, detect::sideband_level_factor(tsa, a, opt));
  EXPECT_DOUBLE_EQ(g.si, detect::sideband_index(a, opt));
  EXPECT_DOUBLE_EQ(g.na4, ens.value(residual));
  EXPECT_DOUBLE_EQ(g.kurtosis, detect::kurtosis(tsa));
  // Without an ensemble NA4 is the residual's kurtosis (an ensemble of one).
  const auto alone = detect::gear_indicators({tsa, {}, {}, residual}, opt);
  EXPECT_NEAR(alone.na4, detect::kurtosis(residual), kRoundOff);
  EXPECT_TRUE(std::isnan(alone.fm4));
  EXPECT_TRUE(std::isnan(alone.er));
  const std::vector<double> short_diff(100, 0.0);
  EXPECT_THROW(detect::gear_indicators({tsa, short_diff, {}, {}}, opt), diag::InputError);
}

}  // namespace
