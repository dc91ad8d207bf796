// ShaftAngle (resample.hpp): the shaft angle between tachometer pulses, a monotone cubic
// Hermite interpolant of the pulse times, and its inverse.
#include <algorithm>
#include <cmath>
#include <string>

#include "detect/angular/resample.hpp"
#include "diag/error.hpp"
#include "resample_internal.hpp"

namespace detect {

namespace {

using diag::fail;
using diag::require;
using resample_internal::hermite;
using resample_internal::hermite_slope;

// Safeguarded Newton on the monotone cubic hermite(s, m0, m1) = q in [0, 1], from s.
double solve_hermite(double q, double m0, double m1, double s) {
  double lo = 0, hi = 1;
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
  return s;
}

}  // namespace

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

double ShaftAngle::max_speed_rev_per_s() const {
  // p'(s) = a s^2 + b s + c on each interval (hermite_slope): its largest value is at an end or
  // at the vertex of a downward parabola.
  double most = *std::max_element(slope_.begin(), slope_.end());
  const double dth = 1.0 / ppr_;
  for (std::size_t i = 0; i + 1 < t_.size(); ++i) {
    const double h = t_[i + 1] - t_[i];
    const double m0 = slope_[i] * h / dth, m1 = slope_[i + 1] * h / dth;
    const double a = -6 + 3 * m0 + 3 * m1, b = 6 - 4 * m0 - 2 * m1;
    if (a < 0) {
      const double s = -b / (2 * a);
      if (s > 0 && s < 1) most = std::max(most, hermite_slope(s, m0, m1) * dth / h);
    }
  }
  return most;
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
  return t_[i] + solve_hermite(q, m0, m1, q) * h;
}

void ShaftAngle::times_at_uniform_angles(double first_revs, int spr, std::span<double> times,
                                         std::span<double> speeds) const {
  require(spr >= 1, "ShaftAngle::times_at_uniform_angles", "samples_per_rev",
          std::to_string(spr) + " is not >= 1");
  require(speeds.empty() || speeds.size() == times.size(), "ShaftAngle::times_at_uniform_angles",
          "speeds_rev_per_s", "is neither empty nor as long as times_s");
  const double total = total_revs();
  const double dth = 1.0 / ppr_;
  std::size_t seg = t_.size();  // the pulse interval of the previous angle (none yet)
  double h = 0, m0 = 0, m1 = 0, s = 0, q_prev = 0;
  for (std::size_t m = 0; m < times.size(); ++m) {
    const double revs = first_revs + static_cast<double>(m) / spr;
    if (!(revs > 0 && revs < total)) {  // extrapolated: rare, at most the ends
      times[m] = time_at(revs);
      if (!speeds.empty()) speeds[m] = speed_rev_per_s(times[m]);
      seg = t_.size();
      continue;
    }
    const double pos = revs * ppr_;
    const std::size_t i = std::min(static_cast<std::size_t>(pos), t_.size() - 2);
    const double q = pos - static_cast<double>(i);
    double guess = q;
    if (i != seg) {
      seg = i;
      h = t_[i + 1] - t_[i];
      m0 = slope_[i] * h / dth;
      m1 = slope_[i + 1] * h / dth;
    } else {
      // One Newton step from the previous angle's solution: the Newton below then converges in
      // one or two evaluations.
      const double df = hermite_slope(s, m0, m1);
      guess = df > 0 ? std::clamp(s + (q - q_prev) / df, s, 1.0) : q;
    }
    s = solve_hermite(q, m0, m1, guess);
    q_prev = q;
    times[m] = t_[i] + s * h;
    if (!speeds.empty()) speeds[m] = hermite_slope(s, m0, m1) * dth / h;
  }
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

}  // namespace detect
