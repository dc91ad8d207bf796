#include "detect/spectral/welch.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "diag/error.hpp"

namespace detect {
namespace {

constexpr std::size_t kMinNperseg = 8;
constexpr std::size_t kMaxNperseg = std::size_t{1} << 24;
constexpr std::size_t kMaxNfft = std::size_t{1} << 26;

// Sum with four independent accumulators: four times the throughput of a single dependent
// chain (the compiler may not reassociate floating-point adds itself).
double sum4(const double* x, std::size_t n) {
  double a = 0, b = 0, c = 0, d = 0;
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    a += x[j];
    b += x[j + 1];
    c += x[j + 2];
    d += x[j + 3];
  }
  for (; j < n; ++j) a += x[j];
  return (a + b) + (c + d);
}

}  // namespace

void WelchOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("welch", "fs_hz", std::to_string(fs_hz) + " is not finite and > 0");
  if (nperseg < kMinNperseg || nperseg > kMaxNperseg)
    diag::fail("welch", "nperseg", std::to_string(nperseg) + " is not in [8, 2^24]");
  if (noverlap < -1 || (noverlap >= 0 && static_cast<std::size_t>(noverlap) >= nperseg))
    diag::fail("welch", "noverlap",
               std::to_string(noverlap) + " is not in [0, nperseg) = [0, " +
                   std::to_string(nperseg) + ") or -1 (nperseg / 2)");
  if (nfft != 0 && (nfft < nperseg || nfft > kMaxNfft))
    diag::fail("welch", "nfft",
               std::to_string(nfft) + " is not 0 or in [nperseg, 2^26] = [" +
                   std::to_string(nperseg) + ", 2^26]");
}

void detrend(std::span<double> x, Detrend type) {
  const std::size_t n = x.size();
  if (n == 0 || type == Detrend::kNone) return;
  const double mean = sum4(x.data(), n) / static_cast<double>(n);
  if (type == Detrend::kConstant) {
    for (double& v : x) v -= mean;
    return;
  }
  // Least-squares line about the centre index c = (n - 1)/2, where the intercept is the mean
  // and the slope is sum (j - c) x_j / sum (j - c)^2, with sum (j - c)^2 = n (n^2 - 1) / 12.
  const double c = 0.5 * static_cast<double>(n - 1);
  double sxy = 0.0;
  for (std::size_t j = 0; j < n; ++j) sxy += (static_cast<double>(j) - c) * x[j];
  const double nd = static_cast<double>(n);
  const double sxx = nd * (nd * nd - 1.0) / 12.0;
  const double slope = n > 1 ? sxy / sxx : 0.0;
  for (std::size_t j = 0; j < n; ++j) x[j] -= mean + slope * (static_cast<double>(j) - c);
}

WelchAccumulator::WelchAccumulator(const WelchOptions& options)
    : options_((options.validate(), options)),
      nperseg_(options.nperseg),
      step_(options.step()),
      nfft_(options.fft_length()),
      window_(*shared_window(options.window, options.nperseg)),
      fft_(nfft_),
      work_(nperseg_),
      power_(fft_.bins(), 0.0),
      pending_(nperseg_, 0.0) {
  // The windowed segment is written into the transform's input buffer, which no transform
  // changes: its zero padding beyond nperseg is written once, here.
  const std::span<double> in = fft_.input();
  std::fill(in.begin() + static_cast<std::ptrdiff_t>(nperseg_), in.end(), 0.0);
  for (double w : window_) {
    window_sum_ += w;
    window_sum_sq_ += w * w;
  }
}

void WelchAccumulator::reset() {
  std::fill(power_.begin(), power_.end(), 0.0);
  pending_size_ = 0;
  segments_ = 0;
  samples_ = 0;
}

void WelchAccumulator::process(const double* segment) {
  const double total = sum4(segment, nperseg_);
  if (!std::isfinite(total))
    diag::fail("welch", "x",
               "non-finite sample (or overflow) in segment " + std::to_string(segments_) +
                   " (samples from " + std::to_string(segments_ * step_) + ")");
  const double* w = window_.data();
  double* y = fft_.input().data();
  switch (options_.detrend) {
    case Detrend::kNone:
      for (std::size_t j = 0; j < nperseg_; ++j) y[j] = w[j] * segment[j];
      break;
    case Detrend::kConstant: {
      const double mean = total / static_cast<double>(nperseg_);
      for (std::size_t j = 0; j < nperseg_; ++j) y[j] = w[j] * (segment[j] - mean);
      break;
    }
    case Detrend::kLinear:
      std::memcpy(y, segment, nperseg_ * sizeof(double));
      detrend(std::span<double>(y, nperseg_), Detrend::kLinear);
      for (std::size_t j = 0; j < nperseg_; ++j) y[j] *= w[j];
      break;
  }
  const std::span<const std::complex<double>> X = fft_.forward_input();
  // std::complex<double> is layout-compatible with double[2] ([complex.numbers]/4).
  const double* z = reinterpret_cast<const double*>(X.data());
  double* p = power_.data();
  const std::size_t bins = power_.size();
  for (std::size_t k = 0; k < bins; ++k) p[k] += z[2 * k] * z[2 * k] + z[2 * k + 1] * z[2 * k + 1];
  ++segments_;
}

void WelchAccumulator::push(std::span<const double> chunk) {
  // The stream seen here is V = pending_[0, P) followed by chunk[0, C); segments start at
  // s = 0, step, 2 step, ... of V while s + nperseg <= P + C.
  const std::size_t P = pending_size_;
  const std::size_t C = chunk.size();
  samples_ += C;
  std::size_t s = 0;
  for (; s + nperseg_ <= P + C; s += step_) {
    if (s >= P) {
      process(chunk.data() + (s - P));
    } else {
      // Spans the boundary: assemble it in work_.
      const std::size_t head = P - s;
      std::memcpy(work_.data(), pending_.data() + s, head * sizeof(double));
      std::memcpy(work_.data() + head, chunk.data(), (nperseg_ - head) * sizeof(double));
      process(work_.data());
    }
  }
  // Keep V[s, P + C): fewer than nperseg samples, the start of the next segment.
  if (s < P) {
    std::memmove(pending_.data(), pending_.data() + s, (P - s) * sizeof(double));
    if (C > 0) std::memcpy(pending_.data() + (P - s), chunk.data(), C * sizeof(double));
    pending_size_ = P - s + C;
  } else {
    const std::size_t from = s - P;
    pending_size_ = C - from;
    if (pending_size_ > 0)
      std::memcpy(pending_.data(), chunk.data() + from, pending_size_ * sizeof(double));
  }
}

Psd WelchAccumulator::result() const {
  for (std::size_t j = 0; j < pending_size_; ++j) {
    if (!std::isfinite(pending_[j]))
      diag::fail("welch", "x",
                 "sample " + std::to_string(samples_ - pending_size_ + j) + " is not finite");
  }
  if (segments_ == 0)
    diag::fail(
        "welch", "x",
        std::to_string(samples_) + " samples is fewer than nperseg = " + std::to_string(nperseg_));
  Psd r;
  r.scaling = options_.scaling;
  r.segments = segments_;
  r.resolution_hz = options_.fs_hz / static_cast<double>(nfft_);
  r.enbw_hz = options_.fs_hz * window_sum_sq_ / (window_sum_ * window_sum_);  // bins x fs/n
  const double scale = options_.scaling == PsdScaling::kDensity
                           ? 1.0 / (options_.fs_hz * window_sum_sq_)
                           : 1.0 / (window_sum_ * window_sum_);
  const double per_segment = scale / static_cast<double>(segments_);
  const std::size_t bins = power_.size();
  r.frequency_hz.resize(bins);
  r.value.resize(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    // One-sided fold: DC, and Nyquist when nfft is even, have no mirror image.
    const bool single = k == 0 || (nfft_ % 2 == 0 && k == bins - 1);
    r.frequency_hz[k] = static_cast<double>(k) * r.resolution_hz;
    r.value[k] = power_[k] * (single ? per_segment : 2.0 * per_segment);
  }
  return r;
}

Psd welch(std::span<const double> x, const WelchOptions& options) {
  WelchAccumulator acc(options);
  acc.push(x);
  return acc.result();
}

}  // namespace detect
