#include "detect/spectral/envelope.hpp"

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

// Analytic signal of x with the bins outside [k_lo, k_hi] zeroed.
std::vector<std::complex<double>> analytic_in_bins(std::span<const double> x, std::size_t k_lo,
                                                   std::size_t k_hi) {
  const std::size_t n = x.size();
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins()), Y(fft.bins());
  fft.forward(x, X);
  const std::size_t nyquist = n % 2 == 0 ? n / 2 : 0;  // 0: no Nyquist bin
  for (std::size_t k = 0; k < X.size(); ++k) {
    if (k < k_lo || k > k_hi) X[k] = 0.0;
    // Hilbert transform: -i sgn(f) X; zero at DC and at Nyquist (h = 1 there: no quadrature).
    Y[k] = (k == 0 || k == nyquist) ? std::complex<double>(0.0)
                                    : std::complex<double>(X[k].imag(), -X[k].real());
  }
  std::vector<double> re(n), im(n);
  fft.inverse(X, re);
  fft.inverse(Y, im);
  std::vector<std::complex<double>> z(n);
  for (std::size_t j = 0; j < n; ++j) z[j] = {re[j], im[j]};
  return z;
}

std::vector<double> magnitude(const std::vector<std::complex<double>>& z) {
  std::vector<double> a(z.size());
  for (std::size_t j = 0; j < z.size(); ++j) a[j] = std::abs(z[j]);
  return a;
}

}  // namespace

std::vector<std::complex<double>> analytic_signal(std::span<const double> x) {
  check_input(x, "analytic_signal");
  return analytic_in_bins(x, 0, x.size() / 2);
}

std::vector<double> envelope(std::span<const double> x) {
  check_input(x, "envelope");
  return magnitude(analytic_in_bins(x, 0, x.size() / 2));
}

std::vector<double> band_envelope(std::span<const double> x, const BandOptions& band) {
  band.validate();
  check_input(x, "band_envelope");
  const double df = band.fs_hz / static_cast<double>(x.size());
  // Bins with low <= k df <= high (a small relative slack keeps a bin that lies exactly on an
  // edge from being lost to round-off in the division).
  const double slack = 1e-9;
  const std::size_t k_lo = static_cast<std::size_t>(std::ceil(band.low_hz / df - slack));
  const std::size_t k_hi = static_cast<std::size_t>(std::floor(band.upper_hz() / df + slack));
  return magnitude(analytic_in_bins(x, k_lo, k_hi));
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

}  // namespace detect
