#include "detect/spectral/filter.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/dsp/fir.hpp"
#include "diag/error.hpp"
#include "diag/util/number_format.hpp"

namespace detect {
namespace {

void check_finite(std::span<const double> x, const char* where) {
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (!std::isfinite(x[j]))
      throw diag::InputError(
          diag::format_error(where, "x", "sample " + std::to_string(j) + " is not finite"));
  }
}

void check_taps(std::span<const double> taps, const char* where) {
  if (taps.empty() || taps.size() % 2 == 0)
    throw diag::InputError(diag::format_error(
        where, "taps", std::to_string(taps.size()) + " taps; need an odd number >= 1"));
}

// Mirror index about the end samples; valid for -n < i < 2n - 1.
inline std::size_t mirror(std::ptrdiff_t i, std::ptrdiff_t n) {
  if (i < 0) i = -i;
  if (i >= n) i = 2 * (n - 1) - i;
  return static_cast<std::size_t>(i);
}

double centred_sum(std::span<const double> x, std::span<const double> h, std::size_t i) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(x.size());
  const std::ptrdiff_t half = static_cast<std::ptrdiff_t>(h.size() / 2);
  const std::ptrdiff_t first = static_cast<std::ptrdiff_t>(i) - half;
  double acc = 0.0;
  if (first >= 0 && first + static_cast<std::ptrdiff_t>(h.size()) <= n) {
    const double* xp = x.data() + first;
    for (std::size_t j = 0; j < h.size(); ++j) acc += h[j] * xp[j];
  } else {
    for (std::size_t j = 0; j < h.size(); ++j)
      acc += h[j] * x[mirror(first + static_cast<std::ptrdiff_t>(j), n)];
  }
  return acc;
}

}  // namespace

void BandOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("band", "fs_hz", diag::format_fixed(fs_hz, 6) + " is not finite and > 0");
  const double hi = upper_hz();
  if (!(std::isfinite(hi) && hi > 0 && hi <= 0.5 * fs_hz))
    diag::fail("band", "high_hz",
               diag::format_fixed(high_hz, 6) + " is not in (low_hz, fs/2] = (" +
                   diag::format_fixed(low_hz, 6) + ", " + diag::format_fixed(0.5 * fs_hz, 6) +
                   "] (or 0 for fs/2)");
  if (!(std::isfinite(low_hz) && low_hz >= 0 && low_hz < hi))
    diag::fail("band", "low_hz",
               diag::format_fixed(low_hz, 6) + " is not in [0, high_hz) = [0, " +
                   diag::format_fixed(hi, 6) + ")");
}

std::vector<double> fft_bandpass(std::span<const double> x, const BandOptions& band) {
  band.validate();
  if (x.size() < 2)
    throw diag::InputError(diag::format_error(
        "fft_bandpass", "x", std::to_string(x.size()) + " samples; need at least 2"));
  check_finite(x, "fft_bandpass");
  const std::size_t n = x.size();
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(x, X);
  const double df = band.fs_hz / static_cast<double>(n);
  const double hi = band.upper_hz();
  for (std::size_t k = 0; k < X.size(); ++k) {
    const double f = static_cast<double>(k) * df;
    // A bin exactly on an edge is kept despite round-off in k df (slack 1e-9 bin).
    if (f < band.low_hz - 1e-9 * df || f > hi + 1e-9 * df) X[k] = 0.0;
  }
  std::vector<double> y(n);
  fft.inverse(X, y);
  return y;
}

void FirLowpassOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("fir_lowpass", "fs_hz", diag::format_fixed(fs_hz, 6) + " is not finite and > 0");
  if (!(std::isfinite(cutoff_hz) && cutoff_hz > 0 && cutoff_hz < 0.5 * fs_hz))
    diag::fail("fir_lowpass", "cutoff_hz",
               diag::format_fixed(cutoff_hz, 6) + " is not in (0, fs/2) = (0, " +
                   diag::format_fixed(0.5 * fs_hz, 6) + ")");
  if (taps < 3 || taps % 2 == 0 || taps > (std::size_t{1} << 16) + 1)
    diag::fail("fir_lowpass", "taps", std::to_string(taps) + " is not odd and in [3, 2^16 + 1]");
}

std::vector<double> design_lowpass_fir(const FirLowpassOptions& options) {
  options.validate();
  diag::LowpassDesign design;
  design.cutoff_fraction = options.cutoff_hz / options.fs_hz;  // cycles per sample
  design.half_length = static_cast<int>(options.taps / 2);
  design.window = diag::FirWindow::kGiven;
  design.window_values = make_window(options.window, options.taps, WindowSymmetry::kSymmetric);
  return diag::design_lowpass(design);
}

std::vector<double> design_decimation_lowpass(double fs_hz, std::size_t factor, std::size_t taps) {
  if (factor < 2)
    throw diag::InputError(diag::format_error("decimation_lowpass", "factor",
                                              std::to_string(factor) + " is not >= 2"));
  if (taps == 0) taps = 64 * factor + 1;
  FirLowpassOptions o;
  o.fs_hz = fs_hz;
  o.taps = taps;
  o.window = WindowType::kBlackmanHarris;
  o.cutoff_hz =
      fs_hz / (2.0 * static_cast<double>(factor)) - 4.0 * fs_hz / static_cast<double>(taps);
  if (!(o.cutoff_hz > 0))
    throw diag::InputError(diag::format_error("decimation_lowpass", "taps",
                                              std::to_string(taps) + " is too few for factor " +
                                                  std::to_string(factor) +
                                                  "; need more than 8 factor"));
  return design_lowpass_fir(o);
}

std::vector<double> filter_zero_phase(std::span<const double> x, std::span<const double> taps) {
  return decimate(x, 1, taps);
}

std::vector<double> decimate(std::span<const double> x, std::size_t factor,
                             std::span<const double> taps) {
  const char* where = factor == 1 ? "filter_zero_phase" : "decimate";
  if (factor == 0) throw diag::InputError(diag::format_error(where, "factor", "0 is not >= 1"));
  check_taps(taps, where);
  if (x.size() <= taps.size() / 2)
    throw diag::InputError(
        diag::format_error(where, "x",
                           std::to_string(x.size()) + " samples; need more than half the taps (" +
                               std::to_string(taps.size() / 2) + ") for the mirrored ends"));
  check_finite(x, where);
  std::vector<double> y((x.size() + factor - 1) / factor);
  for (std::size_t m = 0; m < y.size(); ++m) y[m] = centred_sum(x, taps, m * factor);
  return y;
}

}  // namespace detect
