#include "detect/gear/sidebands.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace {

using std::numbers::pi;

// A mesh signal sampled at 8192 Hz for 8 s (bins of 0.125 Hz): harmonics h = 1..3 of 1000 Hz with
// amplitudes 1, 0.5, 0.25, each modulated in amplitude (depth m) and phase (index beta) once per
// revolution of the modulating shafts, plus white Gaussian noise.
constexpr double kFs = 8192.0;
constexpr std::size_t kN = 65536;
constexpr double kMeshHz = 1000.0;
constexpr double kShaftA = 20.0;  // two shafts 1.7 Hz apart: 13.6 bins, so their sideband lines
constexpr double kShaftB = 21.7;  // at k = 1..3 are 13.6..41 bins apart (separable)
constexpr double kNoiseSd = 0.05;

struct Modulation {
  double shaft_hz;
  double am_depth;  // m
  double pm_index;  // beta [rad]
};

std::vector<double> mesh_signal(const std::vector<Modulation>& mods, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, kNoiseSd);
  const double amp[3] = {1.0, 0.5, 0.25};
  std::vector<double> x(kN);
  for (std::size_t j = 0; j < kN; ++j) {
    const double t = static_cast<double>(j) / kFs;
    double am = 1.0, pm = 0.0;
    for (const Modulation& m : mods) {
      am *= 1.0 + m.am_depth * std::cos(2 * pi * m.shaft_hz * t);
      pm += m.pm_index * std::sin(2 * pi * m.shaft_hz * t);
    }
    double v = 0;
    for (int h = 1; h <= 3; ++h) v += amp[h - 1] * am * std::cos(2 * pi * h * kMeshHz * t + h * pm);
    x[j] = v + g(rng);
  }
  return x;
}

// Hann-windowed single-sided amplitude spectrum: a sine of amplitude A centred on a bin reads A.
struct Spectrum {
  std::vector<double> f, a;
};
Spectrum amplitude_spectrum(const std::vector<double>& x) {
  std::vector<double> w(x.size());
  double sum_w = 0;
  for (std::size_t j = 0; j < x.size(); ++j) {
    const double hann = 0.5 - 0.5 * std::cos(2 * pi * j / x.size());
    w[j] = x[j] * hann;
    sum_w += hann;
  }
  detect::RealFft fft(x.size());
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(w, X);
  Spectrum s;
  s.f.resize(X.size());
  s.a.resize(X.size());
  for (std::size_t k = 0; k < X.size(); ++k) {
    s.f[k] = k * kFs / x.size();
    s.a[k] = 2.0 * std::abs(X[k]) / sum_w;
  }
  return s;
}

const std::vector<detect::ShaftCandidate> kShafts = {{"A", kShaftA}, {"B", kShaftB}};

// Amplitude modulation of depth m puts m/2 of the carrier in each first-order sideband
// (cos a (1 + m cos b) = cos a + m/2 cos(a - b) + m/2 cos(a + b)). With B on a bin (21.75 Hz =
// bin 174) and no phase modulation, the measured lines read 0.1 a_h. Tolerance: the noise in a
// Hann-windowed amplitude bin has rms 4 sigma sqrt(3 / (8 N)) = 4.8e-4; five of those.
TEST(Sidebands, AmplitudeModulationSidebandsReadHalfTheDepth) {
  const double fb = 21.75;
  const auto s = amplitude_spectrum(mesh_signal({{fb, 0.2, 0.0}}, 1));
  const std::vector<detect::ShaftCandidate> shafts = {{"B", fb}};
  const auto r = detect::analyse_sidebands({s.f, s.a}, kMeshHz, shafts);
  const double noise_rms = 4 * kNoiseSd * std::sqrt(3.0 / (8.0 * kN));
  const double kTol = 5 * noise_rms;
  const double amp[3] = {1.0, 0.5, 0.25};
  for (const auto& l : r.shafts[0].lines) {
    const double want = std::abs(l.order) == 1 ? 0.1 * amp[l.harmonic - 1] : 0.0;
    EXPECT_NEAR(l.line.amplitude, want, want > 0 ? kTol : 5 * kTol)  // max of 5 noise bins
        << "h " << l.harmonic << " k " << l.order;
  }
  for (int h = 0; h < 3; ++h) EXPECT_NEAR(r.mesh[h].amplitude, amp[h], kTol);
  EXPECT_EQ(r.status, detect::SidebandStatus::kPointed);
}

// Amplitude and phase modulation at shaft B's frequency: B's family wins, A's (1.7 Hz away) shows
// nothing, in either order of the candidates.
TEST(Sidebands, ModulationAtShaftBPointsAtShaftB) {
  const auto s = amplitude_spectrum(mesh_signal({{kShaftB, 0.2, 0.1}}, 2));
  const auto r = detect::analyse_sidebands({s.f, s.a}, kMeshHz, kShafts);
  ASSERT_EQ(r.status, detect::SidebandStatus::kPointed);
  EXPECT_EQ(r.shafts[r.pointed].name, "B");
  EXPECT_TRUE(r.shafts[1].passes);
  EXPECT_FALSE(r.shafts[0].passes);
  EXPECT_GE(r.shafts[1].detected, 6);  // both first-order sidebands of the three harmonics
  const std::vector<detect::ShaftCandidate> reversed = {kShafts[1], kShafts[0]};
  const auto r2 = detect::analyse_sidebands({s.f, s.a}, kMeshHz, reversed);
  ASSERT_EQ(r2.status, detect::SidebandStatus::kPointed);
  EXPECT_EQ(r2.pointed, 0);
}

// Unmodulated mesh harmonics in noise: no family passes, on any of 10 seeds.
TEST(Sidebands, UnmodulatedMeshPointsAtNothing) {
  for (std::uint64_t seed = 10; seed < 20; ++seed) {
    const auto s = amplitude_spectrum(mesh_signal({}, seed));
    const auto r = detect::analyse_sidebands({s.f, s.a}, kMeshHz, kShafts);
    EXPECT_EQ(r.status, detect::SidebandStatus::kNoSidebands) << "seed " << seed;
    EXPECT_EQ(r.pointed, -1);
  }
}

// Both shafts modulate equally: no shaft is named (kAmbiguous). When A's modulation is 20 dB
// weaker than B's, B is named.
TEST(Sidebands, EqualFamiliesAreAmbiguousAndAClearWinnerIsNamed) {
  const auto both = amplitude_spectrum(mesh_signal({{kShaftA, 0.2, 0.0}, {kShaftB, 0.2, 0.0}}, 3));
  const auto r = detect::analyse_sidebands({both.f, both.a}, kMeshHz, kShafts);
  EXPECT_EQ(r.status, detect::SidebandStatus::kAmbiguous);
  EXPECT_EQ(r.pointed, -1);
  const auto weak_a =
      amplitude_spectrum(mesh_signal({{kShaftA, 0.02, 0.0}, {kShaftB, 0.2, 0.0}}, 4));
  const auto r2 = detect::analyse_sidebands({weak_a.f, weak_a.a}, kMeshHz, kShafts);
  ASSERT_EQ(r2.status, detect::SidebandStatus::kPointed);
  EXPECT_EQ(r2.shafts[r2.pointed].name, "B");
}

// Harmonics beyond the spectrum are reported invalid rather than read out of bounds; bad input is
// an InputError naming the parameter.
TEST(Sidebands, LinesBeyondTheSpectrumAreInvalidAndBadInputIsRejected) {
  const auto s = amplitude_spectrum(mesh_signal({{kShaftB, 0.2, 0.0}}, 5));
  detect::SidebandOptions opt;
  opt.mesh_harmonics = 5;  // 5000 Hz > 4096 Hz Nyquist
  const auto r = detect::analyse_sidebands({s.f, s.a}, kMeshHz, kShafts, opt);
  EXPECT_FALSE(r.mesh[4].valid);
  for (const auto& l : r.shafts[1].lines)
    if (l.harmonic >= 5) {
      EXPECT_FALSE(l.detected);
    }
  EXPECT_EQ(r.shafts[r.pointed].name, "B");
  EXPECT_THROW(detect::analyse_sidebands({s.f, s.a}, 0.0, kShafts), diag::InputError);
  const std::vector<detect::ShaftCandidate> bad = {{"X", -1.0}};
  EXPECT_THROW(detect::analyse_sidebands({s.f, s.a}, kMeshHz, bad), diag::InputError);
  opt.sidebands = 0;
  EXPECT_THROW(opt.validate(), diag::InputError);
}

// An exactly noise-free spectrum: lines on bins and zeros elsewhere, so every local median floor is
// 0. The prominences are measured against the precision floor (the largest line over the dynamic
// range) and read exactly the dynamic range, never the 300 dB clip or infinity; a chosen dynamic
// range is honoured.
TEST(Sidebands, ANoiseFreeSpectrumReadsTheDynamicRangeNotInfinity) {
  constexpr double kRoundOff = 1e-9;  // log10 of exact ratios
  std::vector<double> f(8001), a(8001, 0.0);
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = 0.5 * static_cast<double>(k);
  auto put = [&](double hz, double amp) { a[static_cast<std::size_t>(hz / 0.5)] = amp; };
  for (int h = 1; h <= 3; ++h) {
    put(h * kMeshHz, 1.0);
    put(h * kMeshHz - 20.0, 0.1);  // first-order sidebands of a 20 Hz shaft, -20 dB
    put(h * kMeshHz + 20.0, 0.1);
  }
  const std::vector<detect::ShaftCandidate> shafts = {{"A", 20.0}};
  const auto r = detect::analyse_sidebands({f, a}, kMeshHz, shafts);
  ASSERT_EQ(r.status, detect::SidebandStatus::kPointed);
  for (const auto& l : r.shafts[0].lines) {
    ASSERT_TRUE(l.line.valid);
    EXPECT_EQ(l.line.local_floor, 0.0);
    if (std::abs(l.order) == 1) {
      EXPECT_TRUE(l.detected);
      // 0.1 over 1 x 10^(-120/20): 100 dB.
      EXPECT_NEAR(l.line.prominence_db, detect::kDefaultDynamicRangeDb - 20, kRoundOff);
    }
  }
  for (const auto& m : r.mesh)
    EXPECT_NEAR(m.prominence_db, detect::kDefaultDynamicRangeDb, kRoundOff);
  detect::SidebandOptions opt;
  opt.dynamic_range_db = 60;
  const auto r60 = detect::analyse_sidebands({f, a}, kMeshHz, shafts, opt);
  for (const auto& m : r60.mesh) EXPECT_NEAR(m.prominence_db, 60.0, kRoundOff);
  opt.dynamic_range_db = opt.line_threshold_db;  // nothing could be detected: refused
  EXPECT_THROW(opt.validate(), diag::InputError);
  opt.dynamic_range_db = 301;  // beyond what doubles carry
  EXPECT_THROW(opt.validate(), diag::InputError);
}

// Lines far below the mesh (here -70 dB of its strongest harmonic) stand 50 dB over a noise-free
// floor but are not a defect's sidebands (criterion (b)); lines only at the even orders k = +-2 are
// the orders of a shaft turning twice as fast: no family passes without its first order.
TEST(Sidebands, WeakOrEvenOrderOnlyLinesPointAtNothing) {
  std::vector<double> f(8001), a(8001, 0.0);
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = 0.5 * static_cast<double>(k);
  auto put = [&](double hz, double amp) { a[static_cast<std::size_t>(hz / 0.5)] = amp; };
  for (int h = 1; h <= 3; ++h) {
    put(h * kMeshHz, 1.0);
    for (int k : {-1, 1}) put(h * kMeshHz + k * 20.0, 3e-4);  // -70 dB
  }
  const std::vector<detect::ShaftCandidate> shafts = {{"A", 20.0}};
  const auto weak = detect::analyse_sidebands({f, a}, kMeshHz, shafts);
  EXPECT_EQ(weak.status, detect::SidebandStatus::kNoSidebands);
  EXPECT_EQ(weak.shafts[0].detected, 0);
  EXPECT_GE(weak.shafts[0].lines[2].line.prominence_db, 40.0);  // h 1, k -1: prominent, too weak

  std::fill(a.begin(), a.end(), 0.0);
  for (int h = 1; h <= 3; ++h) {
    put(h * kMeshHz, 1.0);
    for (int k : {-2, 2}) put(h * kMeshHz + k * 20.0, 0.05);  // a 40 Hz shaft's orders
  }
  const auto even = detect::analyse_sidebands({f, a}, kMeshHz, shafts);
  EXPECT_EQ(even.shafts[0].detected, 6);
  EXPECT_FALSE(even.shafts[0].passes);
  detect::SidebandOptions opt;
  opt.require_first_order = false;
  EXPECT_TRUE(detect::analyse_sidebands({f, a}, kMeshHz, shafts, opt).shafts[0].passes);
}

// A second mesh at 1040 Hz: its lines at f_other (= f_mesh + 2 x 20 Hz) and the combination tone
// 2 f_mesh - f_other (960 Hz = f_mesh - 2 x 20 Hz), and their harmonics, sit where a 20 Hz
// shaft's second-order sidebands would. With the other mesh given they are `shared`, not
// detected; without it they count as two more of the shaft's sidebands.
TEST(Sidebands, AnotherMeshAndCombinationTonesAreNotSidebands) {
  constexpr double kOtherHz = 1040.0;
  std::vector<double> f(8001), a(8001, 0.0);
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = 0.5 * static_cast<double>(k);
  auto put = [&](double hz, double amp) { a[static_cast<std::size_t>(hz / 0.5)] = amp; };
  for (int h = 1; h <= 3; ++h) {
    put(h * kMeshHz, 1.0);
    put(h * kOtherHz, 0.3);                             // the other mesh's harmonics
    put(h * kMeshHz - h * (kOtherHz - kMeshHz), 0.05);  // h (2 f_mesh - f_other)
    put(h * kMeshHz + 20.0, 0.05);                      // one genuine first-order line
  }
  const std::vector<detect::ShaftCandidate> shafts = {{"A", 20.0}};
  detect::SidebandOptions opt;
  opt.sidebands = 2;
  const auto alone = detect::analyse_sidebands({f, a}, kMeshHz, shafts, opt);
  EXPECT_EQ(alone.shafts[0].detected, 5);  // three +1 lines, 960 Hz and 1040 Hz
  detect::SidebandContext ctx;
  ctx.other_mesh_hz = {kOtherHz};
  const auto r = detect::analyse_sidebands({f, a}, kMeshHz, shafts, opt, ctx);
  int shared = 0;
  for (const auto& l : r.shafts[0].lines) {
    if (l.harmonic == 1 && std::abs(l.order) == 2) {
      EXPECT_TRUE(l.shared) << "k " << l.order;
    }
    if (l.shared) {
      ++shared;
      EXPECT_FALSE(l.detected);
    }
    if (l.order == 1) {
      EXPECT_FALSE(l.shared);
      EXPECT_TRUE(l.detected);
    }
  }
  EXPECT_GE(shared, 2);
  // Left: the three +1 lines, first-order and genuine: the family still passes on them alone.
  EXPECT_EQ(r.shafts[0].detected, 3);
  const std::vector<double> bad = {-5.0};
  ctx.other_mesh_hz = bad;
  EXPECT_THROW(detect::analyse_sidebands({f, a}, kMeshHz, shafts, opt, ctx), diag::InputError);
}

}  // namespace
