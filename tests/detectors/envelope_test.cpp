// Analytic signal, envelope, envelope spectrum, and the filters they are built on
// (filter.hpp's tests live here: the band-pass is the envelope spectrum's first step).
#include "detect/spectral/envelope.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "detect/spectral/fft.hpp"
#include "detect/spectral/filter.hpp"
#include "diag/error.hpp"

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// AM: A (1 + m cos(2 pi fm t)) cos(2 pi fc t).
std::vector<double> am(double a, double m, double fm, double fc, double fs, std::size_t n) {
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / fs;
    x[j] = a * (1.0 + m * std::cos(kTwoPi * fm * t)) * std::cos(kTwoPi * fc * t);
  }
  return x;
}

// The Hilbert transform of cos is sin: for a whole number of cycles the analytic signal of
// cos(w t) is exp(i w t), to FFT round-off; odd lengths too.
TEST(AnalyticSignal, OfACosineIsTheComplexExponential) {
  constexpr double kRoundOff = 1e-12;
  for (std::size_t n : {1000u, 999u}) {
    std::vector<double> x(n);
    for (std::size_t j = 0; j < n; ++j) x[j] = std::cos(kTwoPi * 37.0 * j / n + 0.4) + 0.25;
    const auto z = detect::analytic_signal(x);
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_NEAR(z[j].real(), x[j], kRoundOff);
      EXPECT_NEAR(z[j].imag(), std::sin(kTwoPi * 37.0 * j / n + 0.4), kRoundOff);  // DC: no H
    }
  }
}

// Against a naive DFT-domain construction inside the test (scipy.signal.hilbert's recipe: h = 1
// at DC and Nyquist, 2 between, 0 above) on random data, even and odd lengths.
TEST(AnalyticSignal, MatchesTheNaiveDftRecipeOnRandomData) {
  constexpr double kRoundOff = 1e-11;  // O(n) naive DFT sums of O(1) terms, n = 64, 65
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g;
  for (std::size_t n : {64u, 65u}) {
    std::vector<double> x(n);
    for (double& v : x) v = g(rng);
    std::vector<std::complex<double>> X(n), z(n);
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t j = 0; j < n; ++j) X[k] += x[j] * std::polar(1.0, -kTwoPi * k * j / n);
    for (std::size_t k = 0; k < n; ++k) {
      const double h = k == 0 || 2 * k == n ? 1.0 : (2 * k < n ? 2.0 : 0.0);
      X[k] *= h;
    }
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t k = 0; k < n; ++k) z[j] += X[k] * std::polar(1.0, kTwoPi * k * j / n);
      z[j] /= static_cast<double>(n);
    }
    const auto got = detect::analytic_signal(x);
    for (std::size_t j = 0; j < n; ++j) EXPECT_NEAR(std::abs(got[j] - z[j]), 0.0, kRoundOff);
  }
}

// The defining test. Carrier 3 kHz modulated at 97 Hz with depth m = 0.4, amplitude 1.7: the
// envelope is 1.7 (1 + 0.4 cos(2 pi 97 t)), so the envelope spectrum reads A m = 0.68 at 97 Hz.
// 1 s at 20 kHz puts every line on a bin and the rectangular window reads exactly (FFT
// round-off). A second AM component (carrier 7 kHz modulated at 150 Hz) lies outside the
// 2-4 kHz band and must not show.
TEST(EnvelopeSpectrum, AmSignalShowsTheModulationLineWithItsAmplitude) {
  constexpr double kRoundOff = 1e-9;  // two 20000-point FFT round trips of O(1) data
  const double fs = 20'000.0;
  const std::size_t n = 20'000;
  auto x = am(1.7, 0.4, 97.0, 3000.0, fs, n);
  const auto other = am(1.0, 0.8, 150.0, 7000.0, fs, n);
  for (std::size_t j = 0; j < n; ++j) x[j] += other[j];
  detect::EnvelopeSpectrumOptions o;
  o.fs_hz = fs;
  o.band_low_hz = 2000.0;
  o.band_high_hz = 4000.0;
  const auto s = detect::envelope_spectrum(x, o);
  EXPECT_DOUBLE_EQ(s.frequency_hz[97], 97.0);
  EXPECT_NEAR(s.amplitude[97], 1.7 * 0.4, kRoundOff);
  EXPECT_NEAR(s.amplitude[150], 0.0, kRoundOff);
  EXPECT_NEAR(s.amplitude[0], 0.0, kRoundOff);  // mean removed
  // Without the band the two envelopes beat: the 150 Hz line appears.
  o.band_low_hz = 0.0;
  o.band_high_hz = 0.0;
  EXPECT_GT(detect::envelope_spectrum(x, o).amplitude[150], 0.1);
}

// The same AM in white noise at a non-bin-centred modulation frequency, read with the flat-top:
// within 1 % of A m. Error budget: flat-top flatness 0.05 %; noise: the band's noise (sigma 0.3
// over 2 kHz of 10 kHz) beats with the carrier into the envelope, a white floor of amplitude
// about 2 sigma sqrt(band/ (fs/2)) sqrt(ENBW / n) ~ 1.4e-3 = 0.2 % of 0.68 per bin.
TEST(EnvelopeSpectrum, AmInNoiseReadsTheModulationDepthWithinOnePercent) {
  constexpr double kRelTol = 0.01;
  const double fs = 20'000.0;
  const std::size_t n = 40'000;
  auto x = am(1.7, 0.4, 97.37, 3000.0, fs, n);
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g(0.0, 0.3);
  for (double& v : x) v += g(rng);
  detect::EnvelopeSpectrumOptions o;
  o.fs_hz = fs;
  o.band_low_hz = 2000.0;
  o.band_high_hz = 4000.0;
  o.window = detect::WindowType::kFlatTop;
  const auto s = detect::envelope_spectrum(x, o);
  double peak = 0.0, f_peak = 0.0;
  for (std::size_t k = 1; k < s.amplitude.size(); ++k) {
    if (s.amplitude[k] > peak) {
      peak = s.amplitude[k];
      f_peak = s.frequency_hz[k];
    }
  }
  EXPECT_NEAR(f_peak, 97.37, 0.5);  // within one 0.5 Hz bin
  EXPECT_NEAR(peak, 0.68, kRelTol * 0.68);
}

TEST(EnvelopeSpectrum, BadBandAndInputsAreNamed) {
  detect::EnvelopeSpectrumOptions o;
  o.fs_hz = 1000.0;
  o.band_low_hz = 300.0;
  o.band_high_hz = 200.0;
  try {
    o.validate();
    FAIL();
  } catch (const diag::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("envelope_spectrum: band_low_hz", 0), 0u) << e.what();
  }
  o.band_high_hz = 600.0;  // above fs/2
  EXPECT_THROW(o.validate(), diag::InputError);
  EXPECT_THROW(detect::envelope(std::vector<double>{1.0}), diag::InputError);
  EXPECT_THROW(detect::envelope(std::vector<double>{1.0, std::nan("")}), diag::InputError);
}

// squared_envelope_spectrum against its definition computed here at the record's own samples
// (|z|^2 of band_envelope, mean removed, the window, amplitude_spectrum) on noise with impulses:
// even and odd lengths, narrow bands (taken at fewer instants: every bin above the band's width
// plus the window's is then 0, to round-off), a wide band reaching Nyquist and the whole band (the
// record's own samples),
// Hann, Hamming and rectangular windows. Tolerance: 1e-9 of the largest line; both are sums of
// ~1e4 O(1) terms through FFTs of different lengths (round-off ~1e-13 relative), the bound
// leaves room for it and nothing else (a missing bin or a wrong scale is O(1)).
TEST(SquaredEnvelopeSpectrum, EqualsTheDefinitionAtTheRecordsSamples) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  const double fs = 20'000.0;
  struct Case {
    std::size_t n;
    double low, high;
    detect::WindowType window;
    bool decimated;
  };
  using W = detect::WindowType;
  for (const Case& c :
       {Case{20'000, 2'000.0, 2'500.0, W::kHann, true},
        Case{19'999, 3'137.0, 3'391.5, W::kHann, true},
        Case{20'000, 6'000.0, 7'000.0, W::kHamming, true},
        Case{20'001, 1'000.0, 1'400.0, W::kRectangular, true},
        Case{20'000, 2'000.0, 10'000.0, W::kHann, true}, Case{20'000, 0.0, 0.0, W::kHann, false}}) {
    std::vector<double> x(c.n);
    for (std::size_t j = 0; j < c.n; ++j) x[j] = g(rng) + (j % 211 == 0 ? 12.0 : 0.0);
    const detect::BandOptions band{fs, c.low, c.high};
    std::vector<double> e = detect::band_envelope(x, band);
    for (double& v : e) v *= v;
    detect::SpectrumOptions so;
    so.fs_hz = fs;
    so.window = c.window;
    so.remove_mean = true;
    const detect::Spectrum want = detect::amplitude_spectrum(e, so);

    detect::RealFft fft(c.n);
    std::vector<std::complex<double>> X(fft.bins());
    fft.forward(x, X);
    const detect::Spectrum got = detect::squared_envelope_spectrum(X, c.n, band, c.window);
    ASSERT_EQ(got.amplitude.size(), want.amplitude.size());
    EXPECT_DOUBLE_EQ(got.resolution_hz, want.resolution_hz);
    EXPECT_NEAR(got.enbw_hz, want.enbw_hz, 1e-9 * want.enbw_hz);
    const double top = *std::max_element(want.amplitude.begin(), want.amplitude.end());
    double worst = 0;
    for (std::size_t k = 0; k < want.amplitude.size(); ++k) {
      EXPECT_DOUBLE_EQ(got.frequency_hz[k], want.frequency_hz[k]);
      worst = std::max(worst, std::abs(got.amplitude[k] - want.amplitude[k]));
    }
    EXPECT_LT(worst, 1e-9 * top) << "n " << c.n << " band " << c.low << "-" << c.high;
    // Taken at fewer instants, the spectrum holds no bins above their Nyquist: zeros there.
    EXPECT_EQ(got.amplitude.back() == 0.0, c.decimated) << "n " << c.n;
    // Given the record itself (Re z of the whole band), the same spectrum.
    const detect::Spectrum with_x = detect::squared_envelope_spectrum(X, c.n, band, c.window, x);
    for (std::size_t k = 0; k < want.amplitude.size(); ++k)
      ASSERT_NEAR(with_x.amplitude[k], want.amplitude[k], 1e-9 * top) << k;
  }
  detect::RealFft fft(64);
  std::vector<std::complex<double>> X(fft.bins());
  EXPECT_THROW(detect::squared_envelope_spectrum(X, 66, {fs, 100.0, 200.0}), diag::InputError);
}

// envelope_spectrum with max_frequency_hz (|z| at fs' >= 2 f_max + 32 B instants, envelope.hpp).
// The reference is the definition (max_frequency_hz 0: |z| at the record's samples), read on the
// same grid k fs / n.
namespace {

struct EnvelopeCase {
  detect::Spectrum want, got;
  double f_max;
};

EnvelopeCase decimated_and_definition(const std::vector<double>& x, double fs, double low,
                                      double high, double f_max) {
  detect::EnvelopeSpectrumOptions o;
  o.fs_hz = fs;
  o.band_low_hz = low;
  o.band_high_hz = high;
  EnvelopeCase c{detect::envelope_spectrum(x, o), {}, f_max};
  o.max_frequency_hz = f_max;
  c.got = detect::envelope_spectrum(x, o);
  return c;
}

// The largest |got - want| over the bins in [0, f_max].
double worst_below(const EnvelopeCase& c) {
  double worst = 0;
  for (std::size_t k = 0; k < c.got.amplitude.size() && c.got.frequency_hz[k] <= c.f_max; ++k)
    worst = std::max(worst, std::abs(c.got.amplitude[k] - c.want.amplitude[k]));
  return worst;
}

}  // namespace

// A noise-free AM signal's envelope A (1 + m cos) is band-limited (it never reaches 0), so at
// fewer instants it is exact: the same spectrum to round-off (1e-9 of the line: sums of ~1e5 O(1)
// terms through FFTs of different lengths, ~1e-13 relative), on the record's grid, up to
// fs'/2 >= f_max + 16 B, and the band's width B = 400 Hz makes len < n. Records of 5 s (whole
// periods of carrier and modulation, so the band holds the AM's three lines and nothing else),
// even and odd lengths.
TEST(EnvelopeSpectrum, AtFewerInstantsEqualsTheDefinitionForABandLimitedEnvelope) {
  const double f_max = 500.0;
  for (const auto& [n, fs] : {std::pair<std::size_t, double>{100'000, 20'000.0},
                              std::pair<std::size_t, double>{99'995, 19'999.0}}) {
    const auto x = am(2.0, 0.5, 60.0, 4'000.0, fs, n);
    const EnvelopeCase c = decimated_and_definition(x, fs, 3'800.0, 4'200.0, f_max);
    ASSERT_LT(c.got.amplitude.size(), c.want.amplitude.size());  // decimated
    const double b = 400.0, df = fs / static_cast<double>(n);
    EXPECT_GE(c.got.frequency_hz.back(), f_max + 16 * b - df);
    EXPECT_DOUBLE_EQ(c.got.resolution_hz, c.want.resolution_hz);
    for (std::size_t k = 0; k < c.got.amplitude.size(); ++k)
      ASSERT_DOUBLE_EQ(c.got.frequency_hz[k], c.want.frequency_hz[k]) << k;
    EXPECT_LT(worst_below(c), 1e-9 * 1.0) << n;  // the line: A m = 1
    const auto line = static_cast<std::size_t>(std::lround(60.0 / df));
    EXPECT_NEAR(c.got.amplitude[line], 1.0, 1e-9);
  }
}

// Gaussian band noise (a Rayleigh envelope, not band-limited) with an AM line: the tail of |z|'s
// spectrum beyond fs'/2 folds onto the kept bins. Bound: the largest difference over [0, f_max]
// stays below 3 % of the definition's median there (measured 0.9 % on the reference recordings,
// envelope.hpp; white noise in a 200 Hz band read to 1 kHz, three seeds, here: the bound leaves
// room for the seeds, not for a wrong scale or grid, which are O(100 %)); the AM line to 1e-3.
TEST(EnvelopeSpectrum, AtFewerInstantsStaysWithinThreePercentOfTheFloorOnBandNoise) {
  const double fs = 20'000.0, f_max = 1'000.0;
  const std::size_t n = 200'000;
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g;
    auto x = am(1.0, 0.5, 37.0, 5'100.0, fs, n);
    for (double& v : x) v += g(rng);
    const EnvelopeCase c = decimated_and_definition(x, fs, 5'000.0, 5'200.0, f_max);
    ASSERT_LT(c.got.amplitude.size(), c.want.amplitude.size() / 2);
    std::vector<double> below;
    for (std::size_t k = 1; c.want.frequency_hz[k] <= f_max; ++k)
      below.push_back(c.want.amplitude[k]);
    std::nth_element(below.begin(), below.begin() + below.size() / 2, below.end());
    const double median = below[below.size() / 2];
    EXPECT_LT(worst_below(c), 0.03 * median) << "seed " << seed;
    const auto line = static_cast<std::size_t>(std::lround(37.0 * n / fs));
    EXPECT_NEAR(c.got.amplitude[line], c.want.amplitude[line], 1e-3 * c.want.amplitude[line]);
  }
  detect::EnvelopeSpectrumOptions o;
  o.fs_hz = fs;
  o.max_frequency_hz = -1.0;
  EXPECT_THROW(detect::envelope_spectrum(std::vector<double>(64, 1.0), o), diag::InputError);
}

// fast_length_at_most: the largest 2^a 3^b 5^c 7^d <= n, by brute force up to 5000, and the loss
// bound the header states (at most n / 64 dropped for n >= 2^16) on a sweep above it.
TEST(FastLength, IsTheLargestSevenSmoothLengthAndLosesAtMostOneSixtyFourth) {
  auto smooth = [](std::size_t v) {
    for (std::size_t p : {2u, 3u, 5u, 7u})
      while (v % p == 0) v /= p;
    return v == 1;
  };
  std::size_t best = 1;
  for (std::size_t n = 1; n <= 5000; ++n) {
    if (smooth(n)) best = n;
    ASSERT_EQ(detect::fast_length_at_most(n), best) << n;
  }
  for (std::size_t n = 1 << 16; n < (1 << 16) + 400'000; n += 97) {
    const std::size_t m = detect::fast_length_at_most(n);
    ASSERT_TRUE(smooth(m) && m <= n && 64 * (n - m) <= n) << n;
  }
  EXPECT_EQ(detect::fast_length_at_most(121'265), 120'960u);  // CWRU IR007: 2^7 3^3 5 7
  const std::vector<double> x(10, 1.0);
  EXPECT_EQ(detect::fast_length_middle(x).data(), x.data() + 0);  // 10 = 2 x 5: whole
  const std::vector<double> y(11, 1.0);
  EXPECT_EQ(detect::fast_length_middle(y).size(), 10u);
  EXPECT_EQ(detect::fast_length_middle(y).data(), y.data());  // (11 - 10) / 2 = 0
}

// ---- filter.hpp ----

// Brick-wall band-pass on whole-period tones: the in-band tone passes exactly, the others go.
TEST(FftBandpass, KeepsInBandTonesExactlyAndRemovesTheRest) {
  constexpr double kRoundOff = 1e-12;
  const double fs = 1000.0;
  const std::size_t n = 1000;
  std::vector<double> x(n), inband(n);
  for (std::size_t j = 0; j < n; ++j) {
    inband[j] = 0.7 * std::sin(kTwoPi * 120.0 * j / fs);
    x[j] = inband[j] + 2.0 + std::cos(kTwoPi * 30.0 * j / fs) + std::sin(kTwoPi * 400.0 * j / fs);
  }
  const auto y = detect::fft_bandpass(x, {fs, 100.0, 200.0});
  for (std::size_t j = 0; j < n; ++j) EXPECT_NEAR(y[j], inband[j], kRoundOff);
}

// Frequency response of the designed low-pass, evaluated naively: H(f) = sum_j h_j e^{-i w j}.
double gain(const std::vector<double>& h, double f_over_fs) {
  std::complex<double> s = 0.0;
  for (std::size_t j = 0; j < h.size(); ++j) s += h[j] * std::polar(1.0, -kTwoPi * f_over_fs * j);
  return std::abs(s);
}

// Windowed-sinc design: symmetric taps (linear phase), unit DC gain, -6 dB at the cut-off (the
// sinc's half-amplitude point, to the window's smoothing: 1 %), and the Blackman-Harris stop band
// below -90 dB from cutoff + 4 fs / taps (half the window's main lobe) on.
TEST(FirLowpass, IsSymmetricWithUnitDcGainAndAStopBandBelowMinus90Db) {
  detect::FirLowpassOptions o;
  o.fs_hz = 1000.0;
  o.cutoff_hz = 100.0;
  o.taps = 201;
  const auto h = detect::design_lowpass_fir(o);
  ASSERT_EQ(h.size(), 201u);
  for (std::size_t j = 0; j < h.size(); ++j) EXPECT_DOUBLE_EQ(h[j], h[h.size() - 1 - j]);
  EXPECT_NEAR(gain(h, 0.0), 1.0, 1e-14);
  EXPECT_NEAR(gain(h, 0.1), 0.5, 0.01);
  const double stop = 0.1 + 4.0 / 201.0;
  for (double f = stop; f <= 0.5; f += 0.0005) EXPECT_LT(gain(h, f), 3.2e-5) << f;  // -90 dB
  EXPECT_THROW((detect::FirLowpassOptions{1000.0, 600.0, 201}).validate(), diag::InputError);
  EXPECT_THROW((detect::FirLowpassOptions{1000.0, 100.0, 200}).validate(), diag::InputError);
}

// design_lowpass_fir is diag::design_lowpass with the window's values; before, it computed
// each tap as w 2 fc sin(2 pi fc t) / (2 pi fc t), which rounds differently from
// sin(2 pi fc t) / (pi t). Tolerance 1e-15 of the largest tap: a few ulps of each tap.
TEST(FirLowpass, MatchesTheFormerDesignToRounding) {
  for (const auto window : {detect::WindowType::kBlackmanHarris, detect::WindowType::kHann}) {
    detect::FirLowpassOptions o;
    o.fs_hz = 1000.0;
    o.cutoff_hz = 120.0;
    o.taps = 129;
    o.window = window;
    const auto h = detect::design_lowpass_fir(o);
    const auto w = detect::make_window(window, o.taps, detect::WindowSymmetry::kSymmetric);
    const double fc = o.cutoff_hz / o.fs_hz;
    const std::ptrdiff_t m = static_cast<std::ptrdiff_t>(o.taps / 2);
    std::vector<double> before(o.taps);
    for (std::ptrdiff_t j = 0; j <= m; ++j) {
      const double t = static_cast<double>(m - j);
      const double sinc = t == 0.0 ? 1.0 : std::sin(kTwoPi * fc * t) / (kTwoPi * fc * t);
      before[static_cast<std::size_t>(j)] = before[static_cast<std::size_t>(2 * m - j)] =
          w[static_cast<std::size_t>(j)] * 2.0 * fc * sinc;
    }
    double sum = 0.0;
    for (double v : before) sum += v;
    for (double& v : before) v /= sum;
    ASSERT_EQ(h.size(), before.size());
    const double kTol = 1e-15 * *std::max_element(before.begin(), before.end());
    for (std::size_t j = 0; j < h.size(); ++j) EXPECT_NEAR(h[j], before[j], kTol) << j;
  }
}

// Zero phase: a pass-band sine comes out with no delay and unit gain (interior samples; the
// mirrored ends are approximate); decimation by 4 keeps a tone at 0.7 of the new Nyquist and
// suppresses one above the new Nyquist below -90 dB (it would alias otherwise).
TEST(FirLowpass, FiltersWithZeroPhaseAndDecimatesWithoutAliasing) {
  const double fs = 4000.0;
  const std::size_t n = 20'000, factor = 4;
  const auto h = detect::design_decimation_lowpass(fs, factor);
  ASSERT_EQ(h.size(), 64 * factor + 1);
  const double f_pass = 0.7 * fs / (2.0 * factor), f_alias = 1.2 * fs / (2.0 * factor);
  std::vector<double> pass(n), both(n);
  for (std::size_t j = 0; j < n; ++j) {
    pass[j] = std::sin(kTwoPi * f_pass * j / fs + 0.2);
    both[j] = pass[j] + std::sin(kTwoPi * f_alias * j / fs);
  }
  const auto y = detect::filter_zero_phase(pass, h);
  constexpr double kPassRipple = 1e-4;  // Blackman-Harris side lobes -92 dB = 2.5e-5, x 4 margin
  for (std::size_t j = h.size(); j + h.size() < n; ++j) EXPECT_NEAR(y[j], pass[j], kPassRipple);
  const auto d = detect::decimate(both, factor, h);
  ASSERT_EQ(d.size(), n / factor);
  for (std::size_t m = h.size(); m + h.size() < d.size(); ++m)
    EXPECT_NEAR(d[m], pass[m * factor], kPassRipple + 3.2e-5) << m;
  EXPECT_THROW(detect::decimate(both, 4, std::vector<double>{1.0, 1.0}), diag::InputError);
  EXPECT_THROW(detect::design_decimation_lowpass(fs, 4, 17), diag::InputError);
}

}  // namespace
