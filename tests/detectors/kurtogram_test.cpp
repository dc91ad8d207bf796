// Spectral kurtosis and the fast kurtogram.
#include "detect/spectral/kurtogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "diag/error.hpp"

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

std::vector<double> gaussian_noise(std::size_t n, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

// A gear-fault-like record: impulses every 10 ms ring a 4 kHz resonance (damping ratio 0.03,
// peak 3.5), under a steady 1 kHz tone of amplitude 3 (the mesh: most of the energy, no
// impulsiveness) and white noise of sigma 1, at 20 kHz.
std::vector<double> faulty_record(std::size_t n, unsigned seed) {
  const double fs = 20'000.0, fn = 4000.0, zeta = 0.03, period_s = 0.010;
  const double wn = kTwoPi * fn, wd = wn * std::sqrt(1.0 - zeta * zeta);
  auto x = gaussian_noise(n, 1.0, seed);
  const std::size_t ring = static_cast<std::size_t>(8.0 / (zeta * wn) * fs);  // 8 time constants
  for (double t0 = 0.0013; t0 * fs < static_cast<double>(n); t0 += period_s) {
    const std::size_t j0 = static_cast<std::size_t>(std::ceil(t0 * fs));
    for (std::size_t j = j0; j < std::min(n, j0 + ring); ++j) {
      const double t = static_cast<double>(j) / fs - t0;
      x[j] += 3.5 * std::exp(-zeta * wn * t) * std::sin(wd * t);
    }
  }
  for (std::size_t j = 0; j < n; ++j) x[j] += 3.0 * std::sin(kTwoPi * 1000.0 * j / fs);
  return x;
}

// A bin-centred tone alone: the band holding it has a constant-magnitude complex envelope,
// K = 1 - 2 = -1 exactly (to round-off), at every level. The record holds whole periods, so no
// end taper (which would modulate the tone) is needed.
TEST(FastKurtogram, SteadyToneReadsMinusOneInItsBandAtEveryLevel) {
  constexpr double kRoundOff = 1e-9;  // round-off bins elsewhere in the band: ~1e-13 relative
  const std::size_t n = 8192;
  const double fs = 8192.0, f = 1000.0;  // bin 1000, away from every band edge below level 5
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j) x[j] = std::sin(kTwoPi * f * j / fs);
  detect::KurtogramOptions o;
  o.fs_hz = fs;
  o.max_level = 4;
  o.taper_fraction = 0.0;
  const auto k = detect::fast_kurtogram(x, o);
  ASSERT_EQ(k.levels.size(), 8u);  // 0, 1, 1.6, 2, 2.6, 3, 3.6, 4
  const std::vector<std::size_t> bands{1, 2, 3, 4, 6, 8, 12, 16};
  for (std::size_t l = 0; l < k.levels.size(); ++l) {
    const auto& row = k.levels[l];
    ASSERT_EQ(row.kurtosis.size(), bands[l]) << l;
    EXPECT_DOUBLE_EQ(row.bandwidth_hz, fs / 2.0 / bands[l]);
    const std::size_t i = static_cast<std::size_t>(f / row.bandwidth_hz);
    EXPECT_NEAR(row.kurtosis[i], -1.0, kRoundOff) << "level " << row.level;
  }
  EXPECT_NEAR(k.levels[2].level, std::log2(3.0), 1e-15);
}

// The defining test: the selected band contains the 4 kHz resonance even though the 1 kHz tone
// carries most of the energy, and its kurtosis is far above the noise bound of the next test.
TEST(FastKurtogram, SelectsTheBandOfTheResonanceRungByImpulses) {
  const std::size_t n = 1 << 17;
  const auto x = faulty_record(n, 21);
  detect::KurtogramOptions o;
  o.fs_hz = 20'000.0;
  o.max_level = 6;
  const auto k = detect::fast_kurtogram(x, o);
  EXPECT_LE(k.low_hz(), 4000.0);
  EXPECT_GE(k.high_hz(), 4000.0);
  EXPECT_GT(k.kurtosis, 1.0);
  // The resonance's half-power bandwidth is 2 zeta fn = 240 Hz; the band should not be wider
  // than a quarter of the spectrum (it would then take in the 1 kHz tone's level 1 band).
  EXPECT_LT(k.bandwidth_hz, 2500.0 + 1e-9);
}

// On stationary Gaussian noise every band's complex envelope is circular Gaussian, K = 0 in
// expectation. The estimate over m independent complex samples has standard deviation 2/sqrt(m)
// (delta method with E|c|^4 = 2, E|c|^6 = 6, E|c|^8 = 24 for unit power: var = (20 - 32 + 16)/m);
// a band holds m = n / 2^(l+1) independent bins, fewest at the deepest level: m = 1024 here,
// sigma = 0.0625. The maximum over all 220 bands stays below 6 sigma = 0.375 (Bonferroni: 220 x
// the 1e-9 Gaussian tail; fixed seeds make the run reproducible anyway).
TEST(FastKurtogram, MaximumKurtosisOfGaussianNoiseStaysSmall) {
  const std::size_t n = 1 << 17;
  detect::KurtogramOptions o;
  o.fs_hz = 20'000.0;
  o.max_level = 6;
  const double m_min = static_cast<double>(n) / std::pow(2.0, o.max_level + 1);
  const double bound = 6.0 * 2.0 / std::sqrt(m_min);
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto k = detect::fast_kurtogram(gaussian_noise(n, 1.0, seed), o);
    EXPECT_LT(k.kurtosis, bound) << "seed " << seed;
    for (const auto& row : k.levels)
      for (double v : row.kurtosis) EXPECT_GT(v, -bound) << "seed " << seed;
  }
}

TEST(FastKurtogram, ShortRecordsAndBadLevelsAreNamed) {
  detect::KurtogramOptions o;
  o.max_level = 0;
  EXPECT_THROW(o.validate(), diag::InputError);
  o.max_level = 6;
  try {
    detect::fast_kurtogram(std::vector<double>(1000, 0.0), o);
    FAIL();
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("kurtogram: x: 1000 samples"), std::string::npos)
        << e.what();
  }
  std::vector<double> x(1 << 13, 0.0);
  x[7] = std::nan("");
  EXPECT_THROW(detect::fast_kurtogram(x, o), diag::InputError);
}

// ---- STFT spectral kurtosis ----

// Gaussian noise: SK = 0 at every interior bin. With 75 % overlap the segments are worth about
// n / nperseg = 4096 independent ones: sigma = 2 / sqrt(4096) = 0.031; 6 sigma bound.
// Faulty record: the segments (1.6 ms) must be shorter than the impulse period (10 ms) for SK to
// see the impulsiveness (Antoni 2006, sec. 5); SK is then largest at the 625 Hz bin nearest
// the 4 kHz resonance, and negative (a tone reads -1) at the 1 kHz mesh tone.
TEST(SpectralKurtosis, IsNearZeroForNoiseAndPeaksAtTheRingingResonance) {
  const std::size_t n = 1 << 17;
  detect::SpectralKurtosisOptions o;
  o.fs_hz = 20'000.0;
  o.nperseg = 32;
  const double bound = 6.0 * 2.0 / std::sqrt(static_cast<double>(n) / o.nperseg);
  const auto noise = detect::spectral_kurtosis(gaussian_noise(n, 1.0, 8), o);
  for (std::size_t k = 1; k + 1 < noise.kurtosis.size(); ++k)
    EXPECT_LT(std::abs(noise.kurtosis[k]), bound) << noise.frequency_hz[k];
  EXPECT_NEAR(noise.kurtosis[0], 1.0, 4.0 * bound);  // DC is real: 3 - 2 (looser: fewer dof)

  const auto sk = detect::spectral_kurtosis(faulty_record(n, 21), o);
  const auto peak = std::max_element(sk.kurtosis.begin() + 1, sk.kurtosis.end() - 1);
  const double f_peak = sk.frequency_hz[static_cast<std::size_t>(peak - sk.kurtosis.begin())];
  EXPECT_NEAR(f_peak, 4000.0, 0.5 * o.fs_hz / o.nperseg);
  EXPECT_GT(*peak, 1.0);
  EXPECT_LT(sk.kurtosis[static_cast<std::size_t>(1000.0 / (o.fs_hz / o.nperseg))], 0.0);
}

}  // namespace

// The bands a caller can use (min_bandwidth_hz, min_low_hz): the levels narrower than
// min_bandwidth_hz are not computed, the bands below min_low_hz read NaN, and every computed band
// has the SAME kurtosis as in the full kurtogram (bit for bit: the same band signal through the
// same transform length). The selection is the largest computed band.
TEST(FastKurtogram, AllowedBandsOnlyGiveTheSameValuesForThoseBands) {
  const std::size_t n = 1 << 15;
  const auto x = faulty_record(n, 5);
  detect::KurtogramOptions o;
  o.fs_hz = 20'000.0;
  o.max_level = 6;
  const auto full = detect::fast_kurtogram(x, o);
  o.min_bandwidth_hz = 1000.0;
  o.min_low_hz = 2600.0;
  const auto part = detect::fast_kurtogram(x, o);
  std::size_t row = 0;
  double best = -1e300;
  for (const auto& lvl : full.levels) {
    if (lvl.bandwidth_hz < o.min_bandwidth_hz) continue;
    ASSERT_LT(row, part.levels.size());
    const auto& p = part.levels[row++];
    EXPECT_EQ(p.level, lvl.level);
    ASSERT_EQ(p.kurtosis.size(), lvl.kurtosis.size());
    for (std::size_t i = 0; i < lvl.kurtosis.size(); ++i) {
      if (static_cast<double>(i) * lvl.bandwidth_hz < o.min_low_hz) {
        EXPECT_TRUE(std::isnan(p.kurtosis[i])) << lvl.level << " " << i;
      } else {
        EXPECT_EQ(p.kurtosis[i], lvl.kurtosis[i]) << lvl.level << " " << i;
        best = std::max(best, lvl.kurtosis[i]);
      }
    }
  }
  EXPECT_EQ(row, part.levels.size());
  EXPECT_EQ(row, 6u);  // levels 0, 1, 1.585, 2, 2.585, 3: bandwidth >= 1000 Hz at 20 kHz
  EXPECT_EQ(part.kurtosis, best);
  // The 4 kHz resonance is still the band chosen among those allowed.
  EXPECT_LE(part.low_hz(), 4000.0);
  EXPECT_GE(part.high_hz(), 4000.0);
  o.min_low_hz = -1.0;
  EXPECT_THROW(detect::fast_kurtogram(x, o), diag::InputError);
}
