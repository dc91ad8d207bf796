#include "detect/angular/order_spectrum.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {

using diag::InputError;

namespace {
void require(bool ok, const std::string& where, const std::string& field,
             const std::string& reason) {
  if (!ok) throw InputError(diag::format_error(where, field, reason));
}
}  // namespace

void OrderSpectrumOptions::validate() const {
  require(segment_revs >= 0, "OrderSpectrumOptions", "segment_revs",
          std::to_string(segment_revs) + " is not >= 0");
  require(overlap >= 0 && overlap <= 0.9, "OrderSpectrumOptions", "overlap",
          std::to_string(overlap) + " is not in [0, 0.9]");
}

OrderSpectrum order_spectrum(const AngleResampled& r, const OrderSpectrumOptions& opt) {
  opt.validate();
  const int spr = r.samples_per_rev;
  require(spr >= 2 && r.revolutions >= 1 &&
              r.samples.size() == static_cast<std::size_t>(r.revolutions) * spr,
          "order_spectrum", "resampled", "holds no whole revolution");
  const int seg_revs = opt.segment_revs == 0 ? r.revolutions : opt.segment_revs;
  require(seg_revs <= r.revolutions, "order_spectrum", "segment_revs",
          std::to_string(seg_revs) + " exceeds the " + std::to_string(r.revolutions) +
              " revolutions held");
  const int hop_revs = std::max(1, static_cast<int>(std::lround(seg_revs * (1 - opt.overlap))));
  const std::size_t n = static_cast<std::size_t>(seg_revs) * spr;

  std::vector<double> w(n, 1.0);
  if (opt.window == OrderSpectrumOptions::Window::kHann) {
    // Periodic Hann: exact amplitude for an order on a line (coherent gain 1/2).
    for (std::size_t j = 0; j < n; ++j) {
      w[j] = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(j) / n);
    }
  }
  double wsum = 0;
  for (double v : w) wsum += v;

  RealFft fft(n);
  std::vector<double> seg(n);
  std::vector<std::complex<double>> spec(fft.bins());
  std::vector<double> power(fft.bins(), 0.0);
  int segments = 0;
  for (int start = 0; start + seg_revs <= r.revolutions; start += hop_revs) {
    const std::size_t off = static_cast<std::size_t>(start) * spr;
    for (std::size_t j = 0; j < n; ++j) seg[j] = r.samples[off + j] * w[j];
    fft.forward(seg, spec);
    for (std::size_t k = 0; k < spec.size(); ++k) {
      const bool single = k == 0 || (n % 2 == 0 && k == n / 2);
      const double a = (single ? 1.0 : 2.0) * std::abs(spec[k]) / wsum;
      power[k] += a * a;
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
