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

}  // namespace

std::size_t smooth_length_at_least(std::size_t n) {
  std::size_t best = std::size_t{1};
  while (best < n) best <<= 1;
  for (std::size_t p5 = 1; p5 < best; p5 *= 5) {
    for (std::size_t p35 = p5; p35 < best; p35 *= 3) {
      std::size_t v = p35;
      while (v < n) v <<= 1;
      best = std::min(best, v);
    }
  }
  return best;
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
}

Spectrum envelope_spectrum(std::span<const double> x, const EnvelopeSpectrumOptions& options) {
  options.validate();
  check_input(x, "envelope_spectrum");
  std::vector<double> env =
      band_envelope(x, {options.fs_hz, options.band_low_hz, options.band_high_hz});
  SpectrumOptions so;
  so.fs_hz = options.fs_hz;
  so.window = options.window;
  so.scaling = options.scaling;
  so.remove_mean = true;
  return amplitude_spectrum(env, so);
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
  RealFft fft(len);
  std::vector<std::complex<double>> work(fft.bins());
  std::vector<double> re(len), im(len);
  band_analytic(X, n, bins, bins.lo, fft, work, re, im);
  for (std::size_t j = 0; j < len; ++j) re[j] = re[j] * re[j] + im[j] * im[j];
  so.fs_hz = band.fs_hz * static_cast<double>(len) / static_cast<double>(n);
  Spectrum s = amplitude_spectrum(re, so);
  // On the record's grid k fs / n, k = 0..n/2: the bins above len/2 are those of a band-limited
  // sequence's spectrum beyond its band, zero.
  s.resolution_hz = band.fs_hz / static_cast<double>(n);
  s.frequency_hz.resize(n / 2 + 1);
  s.amplitude.resize(n / 2 + 1, 0.0);
  for (std::size_t k = 0; k < s.frequency_hz.size(); ++k)
    s.frequency_hz[k] = static_cast<double>(k) * s.resolution_hz;
  return s;
}

}  // namespace detect
