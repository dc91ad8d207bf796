#include "detect/spectral/spectrogram.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <memory>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {
namespace {

WelchOptions as_welch(const SpectrogramOptions& o) {
  WelchOptions w;
  w.fs_hz = o.fs_hz;
  w.nperseg = o.nperseg;
  w.noverlap = o.noverlap;
  w.nfft = o.nfft;
  w.window = o.window;
  w.detrend = o.detrend;
  return w;
}

}  // namespace

void SpectrogramOptions::validate() const {
  try {
    as_welch(*this).validate();
  } catch (const diag::InputError& e) {
    // Same ranges as Welch; report under this function's name.
    std::string msg = e.what();
    if (msg.rfind("welch: ", 0) == 0) msg = msg.substr(7);
    throw diag::InputError("spectrogram: " + msg);
  }
}

Spectrogram spectrogram(std::span<const double> x, const SpectrogramOptions& options) {
  options.validate();
  const WelchOptions wo = as_welch(options);
  const std::size_t nperseg = wo.nperseg, step = wo.step(), nfft = wo.fft_length();
  if (x.size() < nperseg)
    throw diag::InputError(diag::format_error(
        "spectrogram", "x",
        std::to_string(x.size()) + " samples is fewer than nperseg = " + std::to_string(nperseg)));
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (!std::isfinite(x[j]))
      throw diag::InputError(
          diag::format_error("spectrogram", "x", "sample " + std::to_string(j) + " is not finite"));
  }
  const std::shared_ptr<const std::vector<double>> window = shared_window(options.window, nperseg);
  const std::vector<double>& w = *window;
  double wsum = 0, wsum2 = 0;
  for (double v : w) {
    wsum += v;
    wsum2 += v * v;
  }
  const std::size_t segments = (x.size() - nperseg) / step + 1;
  RealFft fft(nfft);
  const std::size_t bins = fft.bins();
  // Segments are written into the transform's input buffer; its zero padding stays (fft.hpp).
  const std::span<double> work = fft.input();
  std::fill(work.begin() + static_cast<std::ptrdiff_t>(nperseg), work.end(), 0.0);

  Spectrogram r;
  r.mode = options.mode;
  r.frequency_hz.resize(bins);
  for (std::size_t k = 0; k < bins; ++k)
    r.frequency_hz[k] = static_cast<double>(k) * options.fs_hz / static_cast<double>(nfft);
  r.time_s.resize(segments);
  r.value.resize(segments * bins);
  const bool psd = options.mode == SpectrogramMode::kPsd;
  const double scale = psd ? 1.0 / (options.fs_hz * wsum2) : 1.0 / wsum;
  for (std::size_t m = 0; m < segments; ++m) {
    const std::size_t start = m * step;
    r.time_s[m] = (static_cast<double>(start) + 0.5 * static_cast<double>(nperseg)) / options.fs_hz;
    std::memcpy(work.data(), x.data() + start, nperseg * sizeof(double));
    detrend(std::span<double>(work.data(), nperseg), options.detrend);
    for (std::size_t j = 0; j < nperseg; ++j) work[j] *= w[j];
    const std::span<const std::complex<double>> X = fft.forward_input();
    double* row = r.value.data() + m * bins;
    for (std::size_t k = 0; k < bins; ++k) {
      const bool single = k == 0 || (nfft % 2 == 0 && k == bins - 1);
      const double fold = single ? 1.0 : 2.0;
      row[k] = psd ? fold * std::norm(X[k]) * scale : fold * magnitude(X[k]) * scale;
    }
  }
  return r;
}

}  // namespace detect
