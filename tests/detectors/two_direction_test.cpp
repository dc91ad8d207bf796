// The two-direction comparison: band energies as tone mean squares, and the normal-to-along
// ratio at the mesh harmonics.
#include "detect/gear/two_direction.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "detect/spectral/spectrum.hpp"
#include "diag/error.hpp"

namespace {

using detect::compare_two_directions;
using detect::Spectrum;
using detect::SpectrumView;

constexpr double kFs = 1000.0;
constexpr std::size_t kN = 10000;  // 10 s: 0.1 Hz bins

std::vector<double> tones(const std::vector<std::pair<double, double>>& freq_amp) {
  std::vector<double> x(kN, 0.0);
  for (std::size_t i = 0; i < kN; ++i) {
    const double t = static_cast<double>(i) / kFs;
    double phase = 0.3;
    for (const auto& [f, a] : freq_amp) {
      x[i] += a * std::sin(2 * M_PI * f * t + phase);
      phase += 1.1;
    }
  }
  return x;
}

Spectrum hann_spectrum(const std::vector<double>& x) {
  detect::SpectrumOptions o;
  o.fs_hz = kFs;
  o.window = detect::WindowType::kHann;
  return detect::amplitude_spectrum(x, o);
}

SpectrumView view(const Spectrum& s) { return {s.frequency_hz, s.amplitude}; }
double enbw_bins(const Spectrum& s) { return s.enbw_hz / s.resolution_hz; }

TEST(TwoDirection, BandEnergyOfABinCentredToneIsItsMeanSquare) {
  // Parseval over the window's whole spectrum: exact up to FFT round-off.
  constexpr double kRelTol = 1e-12;
  const Spectrum s = hann_spectrum(tones({{100.0, 2.0}}));
  const double e = detect::band_mean_square(view(s), enbw_bins(s), 99.0, 101.0);
  EXPECT_NEAR(e, 2.0 * 2.0 / 2, kRelTol * 2.0);
}

TEST(TwoDirection, BandEnergyOfAnOffBinToneIsItsMeanSquareWithinTheSidelobeLoss) {
  // A tone between bins leaks into Hann sidelobes beyond the +-4-bin band; numpy gives a loss of
  // 2.7e-5 of the energy at 0.5 bin offset: 1e-4 bounds it with margin.
  constexpr double kRelTol = 1e-4;
  for (double f : {100.05, 100.03, 100.01}) {
    const Spectrum s = hann_spectrum(tones({{f, 2.0}}));
    const double e = detect::band_mean_square(view(s), enbw_bins(s), f - 0.4, f + 0.4);
    EXPECT_NEAR(e / 2.0, 1.0, kRelTol) << f;
  }
}

TEST(TwoDirection, RatioIsNormalOverAlongEnergyAtTheMeshHarmonicsOnly) {
  // Mesh 50 Hz, harmonics 1..3. A 77 Hz tone on the normal channel is not a mesh harmonic and
  // must not count. Off-harmonic leakage into the bands is below 1e-6 of the energies: 1e-4 dB.
  constexpr double kDbTol = 1e-4;
  const auto along = hann_spectrum(tones({{50, 1.0}, {100, 0.5}, {150, 0.2}}));
  const auto normal = hann_spectrum(tones({{50, 0.1}, {100, 0.3}, {77, 5.0}}));
  const auto r = compare_two_directions(view(along), view(normal), enbw_bins(along), 50.0);
  ASSERT_EQ(r.harmonics.size(), 3u);
  const double ea = (1.0 + 0.25 + 0.04) / 2, en = (0.01 + 0.09) / 2;
  EXPECT_NEAR(r.along_energy, ea, 1e-9);
  EXPECT_NEAR(r.normal_energy, en, 1e-9);
  EXPECT_NEAR(r.normal_to_along_db, 10 * std::log10(en / ea), kDbTol);
  EXPECT_NEAR(r.harmonics[1].normal, 0.09 / 2, 1e-9);
  EXPECT_NEAR(r.harmonics[2].normal, 0.0, 1e-9);
}

TEST(TwoDirection, SwappingTheDirectionsNegatesTheRatio) {
  constexpr double kDbTol = 1e-9;  // the same sums, divided the other way
  const auto a = hann_spectrum(tones({{50, 1.0}, {100, 0.5}}));
  const auto b = hann_spectrum(tones({{50, 0.3}, {100, 1.2}}));
  const auto ab = compare_two_directions(view(a), view(b), enbw_bins(a), 50.0);
  const auto ba = compare_two_directions(view(b), view(a), enbw_bins(a), 50.0);
  EXPECT_NEAR(ab.normal_to_along_db, -ba.normal_to_along_db, kDbTol);
  EXPECT_GT(ab.normal_to_along_db,
            0.0);  // b carries more mesh-harmonic energy: 1.53 vs 1.25 (squared amplitudes)
}

TEST(TwoDirection, HarmonicsBeyondTheSpectrumAreNotSummed) {
  // Mesh 200 Hz, fs 1000 Hz: harmonic 3 (600 Hz) lies above Nyquist.
  const auto a = hann_spectrum(tones({{200, 1.0}}));
  const auto r = compare_two_directions(view(a), view(a), enbw_bins(a), 200.0);
  EXPECT_TRUE(r.harmonics[0].valid);
  EXPECT_FALSE(r.harmonics[2].valid);
  EXPECT_NEAR(r.normal_to_along_db, 0.0, 1e-12);
}

TEST(TwoDirection, AZeroAlongSideIsClippedNotInfinite) {
  const auto a = hann_spectrum(std::vector<double>(kN, 0.0));
  const auto b = hann_spectrum(tones({{50, 1.0}}));
  EXPECT_EQ(compare_two_directions(view(a), view(b), enbw_bins(a), 50.0).normal_to_along_db,
            detect::kMaxProminenceDb);
  EXPECT_TRUE(
      std::isnan(compare_two_directions(view(a), view(a), enbw_bins(a), 50.0).normal_to_along_db));
}

TEST(TwoDirection, BadArgumentsAreRefusedNamingTheField) {
  const auto a = hann_spectrum(tones({{50, 1.0}}));
  EXPECT_THROW(compare_two_directions(view(a), view(a), enbw_bins(a), 0.0), diag::InputError);
  EXPECT_THROW(compare_two_directions(view(a), view(a), 0.0, 50.0), diag::InputError);
  detect::TwoDirectionOptions o;
  o.mesh_harmonics = 0;
  try {
    compare_two_directions(view(a), view(a), enbw_bins(a), 50.0, o);
    FAIL() << "no throw";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh_harmonics"), std::string::npos);
  }
}

}  // namespace
