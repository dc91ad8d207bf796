#include "detect/spectral/spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {
namespace {

constexpr std::size_t kMaxNfft = std::size_t{1} << 28;

}  // namespace

void SpectrumOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("amplitude_spectrum", "fs_hz", std::to_string(fs_hz) + " is not finite and > 0");
  if (nfft > kMaxNfft)
    diag::fail("amplitude_spectrum", "nfft", std::to_string(nfft) + " is not in [0, 2^28]");
}

Spectrum amplitude_spectrum(std::span<const double> x, const SpectrumOptions& options) {
  options.validate();
  const std::size_t n = x.size();
  if (n < 2) diag::fail("amplitude_spectrum", "x", std::to_string(n) + " samples; need at least 2");
  const std::size_t nfft = options.nfft == 0 ? n : options.nfft;
  if (nfft < n)
    diag::fail("amplitude_spectrum", "nfft",
               std::to_string(nfft) + " is shorter than the record (" + std::to_string(n) +
                   " samples); 0 or >= the record length");
  // The sum with four partial sums (no dependency chain); the samples are checked one by one
  // only when the sum is not finite (a non-finite sample makes it so).
  double part[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    for (std::size_t q = 0; q < 4; ++q) part[q] += x[i + q];
  }
  for (; i < n; ++i) part[0] += x[i];
  const double total = (part[0] + part[1]) + (part[2] + part[3]);
  if (!std::isfinite(total)) {
    for (i = 0; i < n; ++i) {
      if (!std::isfinite(x[i]))
        diag::fail("amplitude_spectrum", "x", "sample " + std::to_string(i) + " is not finite");
    }
    if (options.remove_mean)
      diag::fail("amplitude_spectrum", "x", "the sum of the samples overflows (no finite mean)");
  }
  const double mean = options.remove_mean ? total / static_cast<double>(n) : 0.0;

  const SharedWindow window = shared_window_sums(options.window, n);
  const std::vector<double>& w = *window.values;
  const double wsum = window.sum, wsum2 = window.sum_sq;
  // The windowed record goes straight into the transform's own buffer (no zero-initialised
  // copy): samples, then the zero padding.
  RealFft fft(nfft);
  double* buf = fft.input().data();
  for (std::size_t j = 0; j < n; ++j) buf[j] = w[j] * (x[j] - mean);
  std::fill(buf + n, buf + nfft, 0.0);
  const std::span<const std::complex<double>> X = fft.forward_input();

  Spectrum s;
  s.resolution_hz = options.fs_hz / static_cast<double>(nfft);
  const double enbw_bins = static_cast<double>(n) * wsum2 / (wsum * wsum);  // window.hpp
  s.enbw_hz = enbw_bins * options.fs_hz / static_cast<double>(n);
  s.frequency_hz.resize(X.size());
  s.amplitude.resize(X.size());
  const double interior =
      (options.scaling == AmplitudeScaling::kPeak ? 2.0 : std::sqrt(2.0)) / wsum;
  const double edge = 1.0 / wsum;
  for (std::size_t k = 0; k < X.size(); ++k)
    s.frequency_hz[k] = static_cast<double>(k) * s.resolution_hz;
  scaled_magnitudes(X, interior, s.amplitude);
  s.amplitude[0] = magnitude(X[0]) * edge;
  if (nfft % 2 == 0) s.amplitude.back() = magnitude(X.back()) * edge;
  return s;
}

}  // namespace detect
