#include "detect/angular/order_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "detect/spectral/fft.hpp"
#include "detect/spectral/window.hpp"
#include "diag/error.hpp"

namespace detect {

using diag::InputError;

void OrderSpectrumOptions::validate() const {
  diag::require(segment_revs >= 0, "OrderSpectrumOptions", "segment_revs",
                std::to_string(segment_revs) + " is not >= 0");
  diag::require(overlap >= 0 && overlap <= 0.9, "OrderSpectrumOptions", "overlap",
                std::to_string(overlap) + " is not in [0, 0.9]");
  diag::require(max_order >= 0 && std::isfinite(max_order), "OrderSpectrumOptions", "max_order",
                std::to_string(max_order) + " is not >= 0");
}

OrderSpectrum order_spectrum(const AngleResampled& r, const OrderSpectrumOptions& opt) {
  opt.validate();
  const int spr = r.samples_per_rev;
  diag::require(spr >= 2 && r.revolutions >= 1 &&
                    r.samples.size() == static_cast<std::size_t>(r.revolutions) * spr,
                "order_spectrum", "resampled", "holds no whole revolution");
  const int seg_revs = opt.segment_revs == 0 ? r.revolutions : opt.segment_revs;
  diag::require(seg_revs <= r.revolutions, "order_spectrum", "segment_revs",
                std::to_string(seg_revs) + " exceeds the " + std::to_string(r.revolutions) +
                    " revolutions held");
  const int hop_revs = std::max(1, static_cast<int>(std::lround(seg_revs * (1 - opt.overlap))));
  const std::size_t n = static_cast<std::size_t>(seg_revs) * spr;

  // The window shared across channels (spectral/window.hpp: made once per length, its sum in
  // index order); the periodic Hann: exact amplitude for an order on a line (coherent gain 1/2).
  SharedWindow win;
  if (opt.window == OrderSpectrumOptions::Window::kHann)
    win = shared_window_sums(WindowType::kHann, n);
  const double* w = win.values ? win.values->data() : nullptr;
  const double wsum = w ? win.sum : static_cast<double>(n);

  // Only the lines up to max_order are returned: the others are not accumulated.
  std::size_t bins = n / 2 + 1;
  if (opt.max_order > 0)
    bins = std::min(bins, static_cast<std::size_t>(std::floor(opt.max_order * seg_revs)) + 1);
  RealFft fft(n);
  std::vector<double> power(bins, 0.0);
  int segments = 0;
  for (int start = 0; start + seg_revs <= r.revolutions; start += hop_revs) {
    const std::size_t off = static_cast<std::size_t>(start) * spr;
    const std::span<double> seg = fft.input();
    if (w) {
      for (std::size_t j = 0; j < n; ++j) seg[j] = r.samples[off + j] * w[j];
    } else {
      std::copy_n(r.samples.begin() + static_cast<std::ptrdiff_t>(off), n, seg.begin());
    }
    const std::span<const std::complex<double>> spec = fft.forward_input();
    for (std::size_t k = 0; k < bins; ++k) {
      const bool single = k == 0 || (n % 2 == 0 && k == n / 2);
      // (c |X_k| / sum w)^2, c = 1 at order 0 and the Nyquist, else 2.
      const double c = (single ? 1.0 : 2.0) / wsum;
      power[k] += c * c * std::norm(spec[k]);
    }
    ++segments;
  }
  OrderSpectrum out;
  out.segments = segments;
  out.resolution_order = 1.0 / seg_revs;
  out.order.resize(power.size());
  out.amplitude.resize(power.size());
  for (std::size_t k = 0; k < power.size(); ++k) {
    out.order[k] = static_cast<double>(k) / seg_revs;
    out.amplitude[k] = std::sqrt(power[k] / segments);
  }
  return out;
}

}  // namespace detect
