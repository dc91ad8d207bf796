#include "detect/spectral/envelope.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {
namespace {

void check_input(std::span<const double> x, const char* where) {
  if (x.size() < 2)
    throw diag::InputError(
        diag::format_error(where, "x", std::to_string(x.size()) + " samples; need at least 2"));
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (!std::isfinite(x[j]))
      throw diag::InputError(
          diag::format_error(where, "x", "sample " + std::to_string(j) + " is not finite"));
  }
}

// The analytic signal of a record of n samples whose DFT is X (RealFft::forward), restricted to
// the bins [lo, hi], moved down by `shift` bins (z(t) exp(-2 pi i shift t / n): |z| unchanged)
// and evaluated at len equispaced instants t_j = j n / len (in samples of the record):
//   c_j = (1/n) sum_{k=lo..hi} h_k X_k exp(2 pi i (k - shift) j / len),
// h_k = 2 inside (0, n/2), 1 at DC and Nyquist. Needs 0 <= k - shift < len for the band's k
// (shift 0 and len n: the record's own samples, where Re c = the band-passed x and Im c its
// Hilbert transform). The complex inverse DFT of the length-len sequence Z_q (Z_{k - shift} =
// (len / n) h_k X_k) is computed as two real inverse DFTs: re = IDFT(A), im = IDFT(B) with the
// Hermitian parts A_q = (Z_q + conj Z_{-q}) / 2 and B_q = (Z_q - conj Z_{-q}) / (2 i). The two
// are written to re and im (len samples each; re empty: not computed); `work` is len/2 + 1 bins
// of scratch.
void band_analytic(std::span<const std::complex<double>> X, std::size_t n, BandBins bins,
                   std::size_t shift, RealFft& fft, std::span<std::complex<double>> work,
                   std::span<double> re, std::span<double> im) {
  const std::size_t len = fft.size();
  const double scale = static_cast<double>(len) / static_cast<double>(n);
  const std::size_t nyquist = n % 2 == 0 ? n / 2 : 0;  // 0: no Nyquist bin
  auto z = [&](std::size_t q) -> std::complex<double> {
    const std::size_t k = q + shift;
    if (k < bins.lo || k > bins.hi) return 0.0;
    const double h = k == 0 || k == nyquist ? 1.0 : 2.0;
    return len == n ? h * X[k] : (h * scale) * X[k];
  };
  for (int part = re.empty() ? 1 : 0; part < 2; ++part) {
    for (std::size_t q = 0; q < work.size(); ++q) {
      const std::complex<double> zq = z(q), zm = std::conj(z((len - q) % len));
      work[q] = part == 0 ? 0.5 * (zq + zm) : std::complex<double>(0.0, -0.5) * (zq - zm);
    }
    fft.inverse(work, part == 0 ? re : im);
  }
}

// |c| (squared: |c|^2) of band_analytic at the record's own samples, the band not shifted.
// `fft` is a RealFft(n). `record`: empty, or the record itself, which is Re c when the band
// holds every bin (one inverse DFT fewer).
std::vector<double> magnitude_at_samples(std::span<const std::complex<double>> X, BandBins bins,
                                         bool squared, RealFft& fft,
                                         std::span<const double> record = {}) {
  const std::size_t n = fft.size();
  const bool whole = record.size() == n && bins.lo == 0 && bins.hi >= n / 2;
  std::vector<std::complex<double>> work(fft.bins());
  std::vector<double> re(n), im(n);
  if (whole) std::copy(record.begin(), record.end(), re.begin());
  band_analytic(X, n, bins, 0, fft, work, whole ? std::span<double>() : std::span<double>(re), im);
  for (std::size_t j = 0; j < n; ++j) {
    const double p = re[j] * re[j] + im[j] * im[j];  // no overflow: |x| <= DBL_MAX / n
    re[j] = squared ? p : std::sqrt(p);
  }
  return re;
}

// |c| of x's band at x's own samples.
std::vector<double> envelope_of(std::span<const double> x, std::size_t lo, std::size_t hi) {
  RealFft fft(x.size());
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(x, X);
  return magnitude_at_samples(X, {lo, hi}, false, fft);
}

// |c| (squared: |c|^2) of X's band, moved to baseband (|c| unchanged), at len < n instants
// spanning the record, and the amplitude spectrum of those samples on the record's grid
// k fs / n (the len instants span the record's period, so bin k is the same frequency):
// `so.fs_hz` is the record's rate. The spectrum holds max(bins, len/2 + 1) bins; those above
// len/2 are zero.
Spectrum band_magnitude_spectrum(std::span<const std::complex<double>> X, std::size_t n,
                                 BandBins bins, std::size_t len, bool squared, SpectrumOptions so,
                                 std::size_t out_bins) {
  RealFft fft(len);
  std::vector<std::complex<double>> work(fft.bins());
  std::vector<double> re(len), im(len);
  band_analytic(X, n, bins, bins.lo, fft, work, re, im);
  for (std::size_t j = 0; j < len; ++j) {
    const double p = re[j] * re[j] + im[j] * im[j];
    re[j] = squared ? p : std::sqrt(p);
  }
  const double fs = so.fs_hz;
  so.fs_hz = fs * static_cast<double>(len) / static_cast<double>(n);
  Spectrum s = amplitude_spectrum(re, so);
  s.resolution_hz = fs / static_cast<double>(n);
  s.frequency_hz.resize(std::max(out_bins, s.frequency_hz.size()));
  s.amplitude.resize(s.frequency_hz.size(), 0.0);
  for (std::size_t k = 0; k < s.frequency_hz.size(); ++k)
    s.frequency_hz[k] = static_cast<double>(k) * s.resolution_hz;
  return s;
}

}  // namespace

std::size_t smooth_length_at_least(std::size_t n) {
  std::size_t best = 2;
  while (best < n) best <<= 1;
  for (std::size_t p5 = 1; p5 < best; p5 *= 5) {
    for (std::size_t p35 = p5; p35 < best; p35 *= 3) {
      std::size_t v = 2 * p35;  // even
      while (v < n) v <<= 1;
      best = std::min(best, v);
    }
  }
  return best;
}

std::size_t fast_length_at_most(std::size_t n) {
  std::size_t best = n == 0 ? 0 : 1;
  for (std::size_t p7 = 1; p7 <= n; p7 *= 7) {
    for (std::size_t p57 = p7; p57 <= n; p57 *= 5) {
      for (std::size_t p357 = p57; p357 <= n; p357 *= 3) {
        std::size_t v = p357;
        while (v <= n / 2) v <<= 1;
        best = std::max(best, v);
      }
    }
  }
  return best;
}

std::span<const double> fast_length_middle(std::span<const double> x) {
  const std::size_t len = fast_length_at_most(x.size());
  return x.subspan((x.size() - len) / 2, len);
}

BandBins band_bins(std::size_t n, const BandOptions& band) {
  band.validate();
  const double df = band.fs_hz / static_cast<double>(n);
  // Bins with low <= k df <= high (a small relative slack keeps a bin that lies exactly on an
  // edge from being lost to round-off in the division).
  const double slack = 1e-9;
  BandBins b;
  b.lo = static_cast<std::size_t>(std::ceil(band.low_hz / df - slack));
  b.hi = std::min(n / 2, static_cast<std::size_t>(std::floor(band.upper_hz() / df + slack)));
  return b;
}

std::vector<std::complex<double>> analytic_signal(std::span<const double> x) {
  check_input(x, "analytic_signal");
  const std::size_t n = x.size();
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(x, X);
  std::vector<std::complex<double>> work(fft.bins());
  std::vector<double> re(n), im(n);
  band_analytic(X, n, {0, n / 2}, 0, fft, work, re, im);
  std::vector<std::complex<double>> z(n);
  for (std::size_t j = 0; j < n; ++j) z[j] = {re[j], im[j]};
  return z;
}

std::vector<double> envelope(std::span<const double> x) {
  check_input(x, "envelope");
  return envelope_of(x, 0, x.size() / 2);
}

std::vector<double> band_envelope(std::span<const double> x, const BandOptions& band) {
  band.validate();
  check_input(x, "band_envelope");
  const BandBins b = band_bins(x.size(), band);
  return envelope_of(x, b.lo, b.hi);
}

void EnvelopeSpectrumOptions::validate() const {
  BandOptions b{fs_hz, band_low_hz, band_high_hz};
  try {
    b.validate();
  } catch (const diag::InputError& e) {
    std::string msg = e.what();  // "band: low_hz: ..." -> "envelope_spectrum: band_low_hz: ..."
    if (msg.rfind("band: ", 0) == 0) msg = msg.substr(6);
    if (msg.rfind("low_hz", 0) == 0 || msg.rfind("high_hz", 0) == 0) msg = "band_" + msg;
    throw diag::InputError("envelope_spectrum: " + msg);
  }
  if (!(std::isfinite(max_frequency_hz) && max_frequency_hz >= 0))
    throw diag::InputError(
        diag::format_error("envelope_spectrum", "max_frequency_hz",
                           std::to_string(max_frequency_hz) + " is not finite and >= 0"));
}

Spectrum envelope_spectrum(std::span<const double> x, const EnvelopeSpectrumOptions& options) {
  options.validate();
  check_input(x, "envelope_spectrum");
  SpectrumOptions so;
  so.fs_hz = options.fs_hz;
  so.window = options.window;
  so.scaling = options.scaling;
  so.remove_mean = true;
  const std::size_t n = x.size();
  const BandOptions band{options.fs_hz, options.band_low_hz, options.band_high_hz};
  const BandBins bins = band_bins(n, band);
  if (options.max_frequency_hz > 0 && bins.hi >= bins.lo) {
    // |z| at len >= 2 k_max + kEnvelopeAliasBands m + 2 instants (see the header).
    const double df = options.fs_hz / static_cast<double>(n);
    const std::size_t m = bins.hi - bins.lo + 1;
    const auto k_max = static_cast<std::size_t>(std::ceil(options.max_frequency_hz / df));
    const std::size_t len = smooth_length_at_least(2 * k_max + kEnvelopeAliasBands * m + 2);
    if (len < n) {
      RealFft fft(n);
      std::copy(x.begin(), x.end(), fft.input().begin());
      return band_magnitude_spectrum(fft.forward_input(), n, bins, len, false, so, 0);
    }
  }
  return amplitude_spectrum(envelope_of(x, bins.lo, bins.hi), so);
}

Spectrum squared_envelope_spectrum(std::span<const std::complex<double>> X, std::size_t n,
                                   const BandOptions& band, WindowType window,
                                   std::span<const double> record) {
  band.validate();
  if (n < 2 || X.size() != n / 2 + 1)
    throw diag::InputError(diag::format_error("squared_envelope_spectrum", "X",
                                              std::to_string(X.size()) + " bins for n = " +
                                                  std::to_string(n) + "; need n/2 + 1, n >= 2"));
  const BandBins bins = band_bins(n, band);
  SpectrumOptions so;
  so.fs_hz = band.fs_hz;
  so.window = window;
  so.remove_mean = true;
  // Taps of the window's cosine sum (window.hpp) when it is a short one; else none (full rate).
  const std::size_t taps = window == WindowType::kRectangular                              ? 0
                           : window == WindowType::kHann || window == WindowType::kHamming ? 1
                                                                                           : n;
  const std::size_t m = bins.hi >= bins.lo ? bins.hi - bins.lo + 1 : 0;
  const std::size_t len = smooth_length_at_least(2 * (m + taps) + 1);
  if (m == 0 || taps >= n || len >= n) {
    // The record's own samples (the definition; a wide band gains nothing from fewer).
    RealFft fft(n);
    return amplitude_spectrum(magnitude_at_samples(X, bins, true, fft, record), so);
  }
  // |c|^2 at len < n instants (see the header: the same bins, exactly).
  return band_magnitude_spectrum(X, n, bins, len, true, so, n / 2 + 1);
}

}  // namespace detect
