#include "diag/dsp/fir.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "diag/error.hpp"
#include "diag/range_check.hpp"

namespace diag {

namespace {

// 2 fc sinc(2 fc x) = sin(2 pi fc x) / (pi x), the ideal low-pass's impulse response.
double ideal_lowpass(double fc, double x) {
  return x == 0.0 ? 2 * fc : std::sin(2 * std::numbers::pi * fc * x) / (std::numbers::pi * x);
}

}  // namespace

void LowpassDesign::validate() const {
  const std::string w = "lowpass design";
  require_range(cutoff_fraction > 0.0 && cutoff_fraction < 0.5, w, "cutoff_fraction",
                cutoff_fraction, "(0, 0.5)");
  require_range(half_length >= 1, w, "half_length", half_length, ">= 1");
  if (window == FirWindow::kKaiser) {
    require_range(kaiser_beta >= 0.0 && std::isfinite(kaiser_beta), w, "kaiser_beta", kaiser_beta,
                  ">= 0");
  }
  if (window == FirWindow::kGiven) {
    const std::size_t n = 2 * static_cast<std::size_t>(half_length) + 1;
    require(window_values.size() == n, w, "window_values",
            std::to_string(window_values.size()) + " values for " + std::to_string(n) + " taps");
    for (double v : window_values) require(std::isfinite(v), w, "window_values", "not finite");
  }
}

std::vector<double> design_lowpass(const LowpassDesign& design) {
  design.validate();
  const double fc = design.cutoff_fraction;
  const int half_length = design.half_length;
  const int n = 2 * half_length + 1;
  const double i0_beta =
      design.window == FirWindow::kKaiser ? std::cyl_bessel_i(0.0, design.kaiser_beta) : 1.0;
  std::vector<double> h(n);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = i - half_length;
    const double sinc = ideal_lowpass(fc, x);
    switch (design.window) {
      case FirWindow::kBlackman: {
        const double a = 2 * std::numbers::pi * i / (n - 1);
        h[i] = sinc * (0.42 - 0.5 * std::cos(a) + 0.08 * std::cos(2 * a));
        break;
      }
      case FirWindow::kKaiser: {
        const double r = x / half_length;
        h[i] = sinc * std::cyl_bessel_i(0.0, design.kaiser_beta * std::sqrt(1 - r * r)) / i0_beta;
        break;
      }
      case FirWindow::kGiven:
        h[i] = sinc * design.window_values[static_cast<std::size_t>(std::min(i, n - 1 - i))];
        break;
    }
    sum += h[i];
  }
  if (design.unit_dc_gain) {
    for (double& v : h) v /= sum;
  }
  return h;
}

Decimator::Decimator(int factor, double passband_fraction) : factor_(factor) {
  if (factor < 1) {
    throw InputError(format_error("Decimator", "factor", std::to_string(factor) + " is not >= 1"));
  }
  if (!(passband_fraction > 0.0 && passband_fraction < 1.0)) {
    throw InputError(format_error("Decimator", "passband_fraction",
                                  std::to_string(passband_fraction) + " is not in (0, 1)"));
  }
  if (factor == 1) return;  // nothing to filter: output = input
  // Transition band from passband_fraction * fs_out/2 to fs_out/2, in input-rate units.
  const double f_pass = passband_fraction * 0.5 / factor;
  const double f_stop = 0.5 / factor;
  const double transition = f_stop - f_pass;
  // Blackman: transition width ~ 5.5 / N  ->  N = 5.5 / transition; M rounded up to a multiple
  // of the factor so the delay is a whole number of output samples.
  int half = static_cast<int>(std::ceil(5.5 / transition / 2.0));
  half = ((half + factor - 1) / factor) * factor;
  half_ = half;
  LowpassDesign design;  // Blackman, unit DC gain
  design.cutoff_fraction = 0.5 * (f_pass + f_stop);
  design.half_length = half_;
  taps_ = design_lowpass(design);
  history_.assign(taps_.size(), 0.0);
}

void Decimator::emit(std::vector<double>& out) {
  // Output at input index j = next_out_index_ is sum_k h[k] x[j + M - k]; it needs inputs up to
  // j + M, which are all in history_ (the newest at pos_ - 1).
  const std::size_t n = taps_.size();
  std::size_t idx = pos_;  // oldest sample: x[received - n] ... the window x[j - M .. j + M]
  double acc = 0.0;
  // history_ holds x[received - n .. received - 1] with x[received - n] at pos_.
  for (std::size_t k = 0; k < n; ++k) {
    acc += taps_[n - 1 - k] * history_[idx];
    if (++idx == n) idx = 0;
  }
  out.push_back(acc);
}

void Decimator::push(std::span<const double> in, std::vector<double>& out) {
  if (factor_ == 1) {
    out.insert(out.end(), in.begin(), in.end());
    return;
  }
  const std::size_t n = taps_.size();
  for (double x : in) {
    if (received_ == 0) std::fill(history_.begin(), history_.end(), x);  // hold the first value
    history_[pos_] = x;
    if (++pos_ == n) pos_ = 0;
    ++received_;
    last_ = x;
    // The newest input index is received_ - 1 = j + M  ->  j = received_ - 1 - M.
    if (received_ - 1 - half_ == next_out_index_) {
      emit(out);
      next_out_index_ += factor_;
    }
  }
  // Before M inputs have arrived, the first outputs (j = 0, D, ...) see the held first value on
  // their left, which the fill above provides.
}

void Decimator::finish(std::vector<double>& out) {
  if (factor_ == 1) return;
  // Outputs whose right half reaches past the end: extend with the last value.
  const long long end = received_;
  while (next_out_index_ < end) {
    std::vector<double> pad(1, last_);
    push(pad, out);
    if (received_ > end + half_) break;
  }
}

}  // namespace diag
