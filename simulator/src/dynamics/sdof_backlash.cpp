#include "sim/dynamics/sdof_backlash.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/range_check.hpp"
#include "diag/units.hpp"

namespace sim {

using diag::InputError;
using diag::units::kTwoPi;

namespace {

void check_omega(double omega, const char* where) {
  diag::require_range(std::isfinite(omega) && omega > 0.0, where, "omega", omega, "> 0");
}

double backlash_force(double x, double b) {
  if (x > b) return x - b;
  if (x < -b) return x + b;
  return 0.0;
}

}  // namespace

void SdofBacklashOptions::validate(const std::string& where) const {
  diag::require_range(std::isfinite(damping_ratio) && damping_ratio >= 0.0 && damping_ratio < 1.0,
                      where, "damping_ratio", damping_ratio, "[0, 1)");
  diag::require_range(std::isfinite(mean_load) && mean_load >= 0.0, where, "mean_load", mean_load,
                      ">= 0");
  diag::require_range(std::isfinite(half_backlash) && half_backlash >= 0.0, where, "half_backlash",
                      half_backlash, ">= 0");
  double alpha_sum = 0.0;
  for (std::size_t r = 0; r < stiffness.size(); ++r) {
    const Harmonic& h = stiffness[r];
    diag::require_range(std::isfinite(h.amplitude) && std::isfinite(h.phase_rad), where,
                        "stiffness[" + std::to_string(r) + "]", h.amplitude,
                        "finite amplitude and phase");
    alpha_sum += std::abs(h.amplitude);
  }
  diag::require_range(alpha_sum < 1.0, where, "stiffness", alpha_sum,
                      "sum of |alpha_r| < 1 (mesh stiffness must stay positive)");
  for (std::size_t r = 0; r < transmission_error.size(); ++r) {
    const Harmonic& h = transmission_error[r];
    diag::require_range(std::isfinite(h.amplitude) && std::isfinite(h.phase_rad), where,
                        "transmission_error[" + std::to_string(r) + "]", h.amplitude,
                        "finite amplitude and phase");
  }
  diag::require_range(steps_per_period >= 32, where, "steps_per_period", steps_per_period, ">= 32");
  diag::require_range(transient_periods >= 0, where, "transient_periods", transient_periods,
                      ">= 0");
  diag::require_range(record_periods >= 1, where, "record_periods", record_periods, ">= 1");
}

double sdof_acceleration(const SdofBacklashOptions& o, double omega, double tau, double x,
                         double v) {
  double k = 1.0;
  for (std::size_t r = 0; r < o.stiffness.size(); ++r) {
    const double w = omega * static_cast<double>(r + 1);
    k += o.stiffness[r].amplitude * std::cos(w * tau + o.stiffness[r].phase_rad);
  }
  double force = o.mean_load;
  for (std::size_t r = 0; r < o.transmission_error.size(); ++r) {
    const double w = omega * static_cast<double>(r + 1);
    force += o.transmission_error[r].amplitude * w * w *
             std::cos(w * tau + o.transmission_error[r].phase_rad);
  }
  return force - 2.0 * o.damping_ratio * v - k * backlash_force(x, o.half_backlash);
}

SdofState sdof_integrate(const SdofBacklashOptions& o, double omega, SdofState s, int periods,
                         std::vector<double>* samples) {
  check_omega(omega, "sdof_integrate");
  const int n = o.steps_per_period;
  const double h = kTwoPi / omega / n;
  if (samples) samples->reserve(samples->size() + static_cast<std::size_t>(periods) * n);
  for (int p = 0; p < periods; ++p) {
    for (int i = 0; i < n; ++i) {
      // tau restarts every period: the excitation is periodic, and this keeps tau small so the
      // cosines do not lose digits over long runs.
      const double tau = h * i;
      const double k1x = s.v, k1v = sdof_acceleration(o, omega, tau, s.x, s.v);
      const double k2x = s.v + 0.5 * h * k1v;
      const double k2v =
          sdof_acceleration(o, omega, tau + 0.5 * h, s.x + 0.5 * h * k1x, s.v + 0.5 * h * k1v);
      const double k3x = s.v + 0.5 * h * k2v;
      const double k3v =
          sdof_acceleration(o, omega, tau + 0.5 * h, s.x + 0.5 * h * k2x, s.v + 0.5 * h * k2v);
      const double k4x = s.v + h * k3v;
      const double k4v = sdof_acceleration(o, omega, tau + h, s.x + h * k3x, s.v + h * k3v);
      s.x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
      s.v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
      if (samples) samples->push_back(s.x);
    }
  }
  return s;
}

SdofResponse sdof_steady_state(const SdofBacklashOptions& o, double omega, SdofState start,
                               SdofState* end) {
  o.validate("sdof_steady_state");
  check_omega(omega, "sdof_steady_state");
  SdofState s = sdof_integrate(o, omega, start, o.transient_periods);
  std::vector<double> x;
  s = sdof_integrate(o, omega, s, o.record_periods, &x);
  if (end) *end = s;

  SdofResponse r;
  r.omega = omega;
  double sum = 0.0;
  r.x_min = r.x_max = x.front();
  std::size_t separated = 0;
  const double b = o.half_backlash;
  for (double xi : x) {
    sum += xi;
    r.x_min = std::min(r.x_min, xi);
    r.x_max = std::max(r.x_max, xi);
    if (std::abs(xi) <= b) ++separated;
  }
  r.mean = sum / static_cast<double>(x.size());
  double sq = 0.0;
  for (double xi : x) {
    const double d = xi - r.mean;
    sq += d * d;
    r.peak = std::max(r.peak, std::abs(d));
  }
  r.rms = std::sqrt(sq / static_cast<double>(x.size()));
  r.contact_lost = r.x_min < b;
  r.back_impact = r.x_min < -b;
  r.separated_fraction = static_cast<double>(separated) / static_cast<double>(x.size());
  return r;
}

SdofSweep sdof_sweep(const SdofBacklashOptions& o, double omega_min, double omega_max, int points) {
  const char* where = "sdof_sweep";
  o.validate(where);
  diag::require_range(std::isfinite(omega_min) && omega_min > 0.0, where, "omega_min", omega_min,
                      "> 0");
  diag::require_range(std::isfinite(omega_max) && omega_max > omega_min, where, "omega_max",
                      omega_max, "> omega_min");
  diag::require_range(points >= 2, where, "points", points, ">= 2");
  SdofSweep sweep;
  sweep.up.reserve(static_cast<std::size_t>(points));
  sweep.down.reserve(static_cast<std::size_t>(points));
  const double step = (omega_max - omega_min) / (points - 1);
  SdofState s{o.half_backlash + o.mean_load, 0.0};
  for (int i = 0; i < points; ++i) {
    sweep.up.push_back(sdof_steady_state(o, omega_min + step * i, s, &s));
  }
  for (int i = points - 1; i >= 0; --i) {
    sweep.down.push_back(sdof_steady_state(o, omega_min + step * i, s, &s));
  }
  return sweep;
}

}  // namespace sim
