#include "detect/angular/resample.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "diag/error.hpp"

namespace detect {

using diag::InputError;

namespace {

using diag::fail;
using diag::require;

// Cubic Hermite basis on [0, 1]: p(s) = H01(s) + m0 H10(s) + m1 H11(s) goes from 0 to 1 with
// slopes m0, m1 (slopes normalised by the secant).
double hermite(double s, double m0, double m1) {
  const double s2 = s * s, s3 = s2 * s;
  return (-2 * s3 + 3 * s2) + m0 * (s3 - 2 * s2 + s) + m1 * (s3 - s2);
}
double hermite_slope(double s, double m0, double m1) {
  const double s2 = s * s;
  return (-6 * s2 + 6 * s) + m0 * (3 * s2 - 4 * s + 1) + m1 * (3 * s2 - 2 * s);
}

// The interpolation kernel as a function of r = (u - n) / K in [-1, 1]: since g (u - n) = Z r,
// sinc(g (u - n)) w((u - n) / K) = sinc(Z r) w(r) does not depend on the cutoff, so one table
// serves every speed. w is the Kaiser window I0(beta sqrt(1 - r^2)) / I0(beta). The table has
// 512 points per zero crossing, read with linear interpolation: error <= (pi Z)^2 (1/(512 Z))^2 / 8
// = 5e-6 of the kernel's peak.
class KernelTable {
 public:
  KernelTable(int zero_crossings, double beta)
      : size_(512 * zero_crossings), h_(static_cast<std::size_t>(size_) + 2, 0.0) {
    const double norm = std::cyl_bessel_i(0.0, beta);
    for (int i = 0; i <= size_; ++i) {
      const double r = static_cast<double>(i) / size_;
      const double x = std::numbers::pi * zero_crossings * r;
      const double sinc = i == 0 ? 1.0 : std::sin(x) / x;
      h_[i] = sinc * std::cyl_bessel_i(0.0, beta * std::sqrt(std::max(0.0, 1 - r * r))) / norm;
    }
    // h_[size_ + 1] stays 0: r == 1 exactly reads a zero neighbour.
  }
  double operator()(double r) const {  // r in [0, 1]
    const double p = r * size_;
    const auto i = static_cast<std::size_t>(p);
    const double f = p - static_cast<double>(i);
    return h_[i] + f * (h_[i + 1] - h_[i]);
  }

 private:
  int size_;
  std::vector<double> h_;
};

// Kaiser beta for 80 dB stopband (Kaiser's formula 0.1102 (A - 8.7)), and the matching
// transition width relative to the cutoff for Z zero crossings: (A - 8) / (2.285 * 2 pi * Z).
constexpr double kKaiserBeta = 0.1102 * (80.0 - 8.7);
double transition_rel(int zero_crossings) {
  return (80.0 - 8.0) / (2.285 * 2 * std::numbers::pi * zero_crossings);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ShaftAngle

ShaftAngle::ShaftAngle(std::span<const double> t, int pulses_per_rev) : ppr_(pulses_per_rev) {
  require(pulses_per_rev >= 1, "ShaftAngle", "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(t.size() >= static_cast<std::size_t>(pulses_per_rev) + 1, "ShaftAngle", "pulse_times_s",
          "has " + std::to_string(t.size()) + " pulses; one revolution needs " +
              std::to_string(pulses_per_rev + 1));
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]))
      fail("ShaftAngle", "pulse_times_s", "pulse " + std::to_string(i) + " is NaN or Inf");
    if (i > 0 && !(t[i] > t[i - 1]))
      fail("ShaftAngle", "pulse_times_s", "not strictly increasing at pulse " + std::to_string(i));
  }
  t_.assign(t.begin(), t.end());
  const std::size_t n = t_.size();
  const double dth = 1.0 / ppr_;
  slope_.resize(n);
  if (n == 2) {
    slope_[0] = slope_[1] = dth / (t_[1] - t_[0]);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    // The parabola through three consecutive pulses, differentiated at pulse i.
    const std::size_t c = std::clamp<std::size_t>(i, 1, n - 2);
    const double h0 = t_[c] - t_[c - 1], h1 = t_[c + 1] - t_[c];
    const double s0 = dth / h0, s1 = dth / h1;
    double d, smin;
    if (i == c) {
      d = (h1 * s0 + h0 * s1) / (h0 + h1);
      smin = std::min(s0, s1);
    } else if (i < c) {
      d = ((2 * h0 + h1) * s0 - h0 * s1) / (h0 + h1);
      smin = s0;
    } else {
      d = ((2 * h1 + h0) * s1 - h1 * s0) / (h0 + h1);
      smin = s1;
    }
    slope_[i] = std::clamp(d, 0.0, 3 * smin);  // Fritsch-Carlson: monotone on both sides
  }
}

double ShaftAngle::total_revs() const { return static_cast<double>(t_.size() - 1) / ppr_; }

std::size_t ShaftAngle::interval_of_time(double t) const {
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - t_.begin());
  return std::clamp<std::size_t>(k == 0 ? 0 : k - 1, 0, t_.size() - 2);
}

double ShaftAngle::revs_at(double t) const {
  const double dth = 1.0 / ppr_;
  if (t <= t_.front()) return (t - t_.front()) * slope_.front();
  if (t >= t_.back()) return total_revs() + (t - t_.back()) * slope_.back();
  const std::size_t i = interval_of_time(t);
  const double h = t_[i + 1] - t_[i];
  const double s = (t - t_[i]) / h;
  return (static_cast<double>(i) + hermite(s, slope_[i] * h / dth, slope_[i + 1] * h / dth)) * dth;
}

double ShaftAngle::speed_rev_per_s(double t) const {
  if (t <= t_.front()) return slope_.front();
  if (t >= t_.back()) return slope_.back();
  const double dth = 1.0 / ppr_;
  const std::size_t i = interval_of_time(t);
  const double h = t_[i + 1] - t_[i];
  const double s = (t - t_[i]) / h;
  return hermite_slope(s, slope_[i] * h / dth, slope_[i + 1] * h / dth) * dth / h;
}

double ShaftAngle::time_at(double revs) const {
  const double total = total_revs();
  // Linear extrapolation beyond the pulses; a zero end slope cannot be inverted, use the secant.
  if (revs <= 0) {
    const double sl = slope_.front() > 0 ? slope_.front() : (1.0 / ppr_) / (t_[1] - t_[0]);
    return t_.front() + revs / sl;
  }
  if (revs >= total) {
    const std::size_t n = t_.size();
    const double sl = slope_.back() > 0 ? slope_.back() : (1.0 / ppr_) / (t_[n - 1] - t_[n - 2]);
    return t_.back() + (revs - total) / sl;
  }
  const double pos = revs * ppr_;
  const std::size_t i = std::min(static_cast<std::size_t>(pos), t_.size() - 2);
  const double q = pos - static_cast<double>(i);  // target of p(s), in [0, 1]
  const double h = t_[i + 1] - t_[i];
  const double dth = 1.0 / ppr_;
  const double m0 = slope_[i] * h / dth, m1 = slope_[i + 1] * h / dth;
  // Safeguarded Newton on the monotone cubic p(s) = q, bracket [lo, hi].
  double lo = 0, hi = 1, s = q;
  for (int it = 0; it < 60; ++it) {
    const double f = hermite(s, m0, m1) - q;
    if (std::abs(f) <= 4e-16) break;  // p is in [0, 1]: a few ulps
    if (f > 0)
      hi = s;
    else
      lo = s;
    const double df = hermite_slope(s, m0, m1);
    double next = df > 0 ? s - f / df : 0.5 * (lo + hi);
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - s) <= 1e-15;
    s = next;
    if (done) break;
  }
  return t_[i] + s * h;
}

std::vector<double> scale_pulses(std::span<const double> pulse_times_s, double ratio,
                                 int pulses_per_rev) {
  require(ratio > 0 && std::isfinite(ratio), "scale_pulses", "ratio",
          std::to_string(ratio) + " is not > 0");
  const ShaftAngle a(pulse_times_s, pulses_per_rev);
  // Relative slack of 1e-9 keeps the last revolution when ratio * total is an integer.
  const auto k_max = static_cast<long>(std::floor(ratio * a.total_revs() * (1 + 1e-12) + 1e-9));
  std::vector<double> out(static_cast<std::size_t>(k_max + 1));
  for (long k = 0; k <= k_max; ++k) out[static_cast<std::size_t>(k)] = a.time_at(k / ratio);
  return out;
}

// ---------------------------------------------------------------------------------------------
// resample_by_angle

void ResampleOptions::validate() const {
  const std::string w = "ResampleOptions";
  require(samples_per_rev >= 8, w, "samples_per_rev",
          std::to_string(samples_per_rev) + " is not >= 8");
  require(pulses_per_rev >= 1, w, "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(kernel_zero_crossings >= 4 && kernel_zero_crossings <= 64, w, "kernel_zero_crossings",
          std::to_string(kernel_zero_crossings) + " is not in [4, 64]");
}

AngleResampled resample_by_angle(std::span<const double> x, double fs_hz,
                                 std::span<const double> pulse_times_s,
                                 const ResampleOptions& opt) {
  opt.validate();
  require(fs_hz > 0 && std::isfinite(fs_hz), "resample_by_angle", "fs_hz",
          std::to_string(fs_hz) + " is not > 0");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]))
      fail("resample_by_angle", "x", "sample " + std::to_string(i) + " is NaN or Inf");
  }
  const ShaftAngle angle(pulse_times_s, opt.pulses_per_rev);
  const int spr = opt.samples_per_rev;
  const int z = opt.kernel_zero_crossings;
  const double guard = 1 + 0.5 * transition_rel(z);
  const double last_sample = static_cast<double>(x.size()) - 1;

  // Kernel cutoff g = 2 f_c / fs (cycles per sample x 2) and half-width K = z / g [samples].
  // The speed is floored at a tenth of the record's mean: the monotonicity limiter may set a zero
  // slope at an end pulse, which would ask for an infinitely long kernel.
  const double speed_floor =
      0.1 * angle.total_revs() / (angle.last_pulse_s() - angle.first_pulse_s());
  auto cutoff = [&](double t) {
    const double f = std::max(angle.speed_rev_per_s(t), speed_floor);
    const double f_nyq = std::min(0.5 * spr * f, 0.5 * fs_hz);
    return 2 * (f_nyq / guard) / fs_hz;
  };

  // Whole revolutions whose boundaries have the kernel inside the record.
  const auto total = static_cast<long>(std::floor(angle.total_revs() + 1e-9));
  long first = -1, last = -1;
  double margin_s = 0;
  for (long k = 0; k <= total; ++k) {
    const double t = angle.time_at(static_cast<double>(k));
    const double half = z / cutoff(t);
    margin_s = std::max(margin_s, half / fs_hz);
    if (t * fs_hz - half >= 0) {
      first = k;
      break;
    }
  }
  for (long k = total; k >= 0; --k) {
    const double t = angle.time_at(static_cast<double>(k));
    const double half = z / cutoff(t);
    margin_s = std::max(margin_s, half / fs_hz);
    if (t * fs_hz + half <= last_sample) {
      last = k;
      break;
    }
  }
  require(first >= 0 && last > first, "resample_by_angle", "pulse_times_s",
          "no whole revolution lies inside the record with the interpolation filter's margin of " +
              std::to_string(margin_s) + " s on each side");

  AngleResampled out;
  out.samples_per_rev = spr;
  out.first_rev = static_cast<double>(first);
  out.revolutions = static_cast<int>(last - first);
  out.samples.resize(static_cast<std::size_t>(out.revolutions) * spr);

  const KernelTable kernel(z, kKaiserBeta);
  const long n_max = static_cast<long>(x.size()) - 1;
  for (std::size_t m = 0; m < out.samples.size(); ++m) {
    const double theta = out.first_rev + static_cast<double>(m) / spr;
    const double t = angle.time_at(theta);
    const double g = cutoff(t);
    const double half = z / g;
    const double inv_half = g / z;
    const double u = t * fs_hz;
    const long n0 = std::max<long>(0, static_cast<long>(std::ceil(u - half)));
    const long n1 = std::min<long>(n_max, static_cast<long>(std::floor(u + half)));
    double acc = 0;
    for (long n = n0; n <= n1; ++n) {
      const double r = std::abs(u - static_cast<double>(n)) * inv_half;
      if (r < 1) acc += x[static_cast<std::size_t>(n)] * kernel(r);
    }
    out.samples[m] = g * acc;
  }
  return out;
}

}  // namespace detect
