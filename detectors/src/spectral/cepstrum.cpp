#include "detect/spectral/cepstrum.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {
void CepstrumOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("cepstrum", "fs_hz", std::to_string(fs_hz) + " is not finite and > 0");
  if (nfft > (std::size_t{1} << 28))
    diag::fail("cepstrum", "nfft", std::to_string(nfft) + " is not in [0, 2^28]");
  if (!(floor_relative > 0 && floor_relative < 1))
    diag::fail("cepstrum", "floor_relative", std::to_string(floor_relative) + " is not in (0, 1)");
}

Cepstrum real_cepstrum(std::span<const double> x, const CepstrumOptions& options) {
  options.validate();
  const std::size_t n = x.size();
  if (n < 2) diag::fail("cepstrum", "x", std::to_string(n) + " samples; need at least 2");
  const std::size_t nfft = options.nfft == 0 ? n : options.nfft;
  if (nfft < n)
    diag::fail("cepstrum", "nfft",
               std::to_string(nfft) + " is shorter than the record (" + std::to_string(n) +
                   " samples); 0 or >= the record length");
  const std::shared_ptr<const std::vector<double>> window = shared_window(options.window, n);
  const std::vector<double>& w = *window;
  std::vector<double> buf(nfft, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    if (!std::isfinite(x[j]))
      diag::fail("cepstrum", "x", "sample " + std::to_string(j) + " is not finite");
    buf[j] = w[j] * x[j];
  }
  RealFft fft(nfft);
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(buf, X);
  double peak = 0.0;
  for (const auto& v : X) peak = std::max(peak, magnitude(v));
  if (peak == 0.0)
    diag::fail("cepstrum", "x", "all samples are zero (the log spectrum is undefined)");
  const double floor = options.floor_relative * peak;
  for (auto& v : X) v = std::log(std::max(magnitude(v), floor));
  fft.inverse(X, buf);

  Cepstrum c;
  const std::size_t half = nfft / 2 + 1;
  c.quefrency_s.resize(half);
  c.value.assign(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(half));
  for (std::size_t q = 0; q < half; ++q) c.quefrency_s[q] = static_cast<double>(q) / options.fs_hz;
  return c;
}

}  // namespace detect
