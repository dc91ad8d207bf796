#include "sim/dynamics/speed_profile.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/range_check.hpp"
#include "diag/units.hpp"
#include "diag/util/number_format.hpp"

namespace sim {
namespace {

constexpr double kRpmToRadPerS = 2.0 * 3.14159265358979323846 / 60.0;

// Speeds and durations: finite and > 0.
void require_positive(double v, const std::string& where, const std::string& field) {
  diag::require_range(v > 0.0 && std::isfinite(v), where, field, v, "> 0");
}

}  // namespace

SpeedProfile SpeedProfile::constant(double rpm) {
  SpeedProfile p;
  p.kind = Kind::kConstant;
  p.rpm = rpm;
  return p;
}

SpeedProfile SpeedProfile::ramp(double from_rpm, double to_rpm, double start_s, double duration_s) {
  SpeedProfile p;
  p.kind = Kind::kRamp;
  p.from_rpm = from_rpm;
  p.to_rpm = to_rpm;
  p.start_s = start_s;
  p.duration_s = duration_s;
  return p;
}

void SpeedProfile::validate(const std::string& where) const {
  switch (kind) {
    case Kind::kConstant:
      require_positive(rpm, where, "rpm");
      break;
    case Kind::kRamp:
      require_positive(from_rpm, where, "from_rpm");
      require_positive(to_rpm, where, "to_rpm");
      require_positive(duration_s, where, "duration_s");
      if (!(start_s >= 0.0)) {
        throw diag::InputError(diag::format_error(where, "start_s", "must be >= 0"));
      }
      break;
    case Kind::kMeasured:
      if (time_s.size() < 2 || time_s.size() != rpm_values.size()) {
        throw diag::InputError(
            diag::format_error(where, "profile", "needs >= 2 (time_s, rpm) points of equal count"));
      }
      if (time_s[0] != 0.0) {
        throw diag::InputError(diag::format_error(where, "time_s[0]", "must be 0"));
      }
      for (std::size_t i = 0; i < time_s.size(); ++i) {
        require_positive(rpm_values[i], where, "rpm[" + std::to_string(i) + "]");
        if (i > 0 && !(time_s[i] > time_s[i - 1])) {
          throw diag::InputError(diag::format_error(where, "time_s[" + std::to_string(i) + "]",
                                                    "times must increase strictly"));
        }
      }
      break;
  }
  // Documented bound (docs/limits.md): beyond it the step per output sample overflows and the
  // run would take days.
  if (max_rpm() > diag::kMaxSpeedRpm) {
    throw diag::InputError(diag::format_error(where, "rpm",
                                              diag::format_significant(max_rpm(), 6) +
                                                  " rpm exceeds " +
                                                  diag::format_significant(diag::kMaxSpeedRpm, 6)));
  }
}

double SpeedProfile::speed_rad_per_s(double t) const {
  switch (kind) {
    case Kind::kConstant:
      return rpm * kRpmToRadPerS;
    case Kind::kRamp: {
      const double x = std::clamp((t - start_s) / duration_s, 0.0, 1.0);
      return (from_rpm + (to_rpm - from_rpm) * x) * kRpmToRadPerS;
    }
    case Kind::kMeasured: {
      if (t <= time_s.front()) return rpm_values.front() * kRpmToRadPerS;
      if (t >= time_s.back()) return rpm_values.back() * kRpmToRadPerS;
      const auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - time_s.begin()) - 1;
      const double x = (t - time_s[i]) / (time_s[i + 1] - time_s[i]);
      return (rpm_values[i] + (rpm_values[i + 1] - rpm_values[i]) * x) * kRpmToRadPerS;
    }
  }
  return 0.0;
}

double SpeedProfile::acceleration_rad_per_s2(double t) const {
  switch (kind) {
    case Kind::kConstant:
      return 0.0;
    case Kind::kRamp:
      if (t < start_s || t >= start_s + duration_s) return 0.0;
      return (to_rpm - from_rpm) / duration_s * kRpmToRadPerS;
    case Kind::kMeasured: {
      if (t < time_s.front() || t >= time_s.back()) return 0.0;
      const auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - time_s.begin()) - 1;
      return (rpm_values[i + 1] - rpm_values[i]) / (time_s[i + 1] - time_s[i]) * kRpmToRadPerS;
    }
  }
  return 0.0;
}

double SpeedProfile::angle_rad(double t) const {
  switch (kind) {
    case Kind::kConstant:
      return rpm * kRpmToRadPerS * t;
    case Kind::kRamp: {
      const double w0 = from_rpm * kRpmToRadPerS, w1 = to_rpm * kRpmToRadPerS;
      if (t <= start_s) return w0 * t;
      const double a = w0 * start_s;
      if (t <= start_s + duration_s) {
        const double tau = t - start_s;
        return a + w0 * tau + 0.5 * (w1 - w0) / duration_s * tau * tau;
      }
      return a + 0.5 * (w0 + w1) * duration_s + w1 * (t - start_s - duration_s);
    }
    case Kind::kMeasured: {
      double angle = 0.0;
      for (std::size_t i = 0; i + 1 < time_s.size(); ++i) {
        const double t0 = time_s[i], t1 = time_s[i + 1];
        if (t <= t0) break;
        const double w0 = rpm_values[i] * kRpmToRadPerS, w1 = rpm_values[i + 1] * kRpmToRadPerS;
        const double tau = std::min(t, t1) - t0;
        angle += w0 * tau + 0.5 * (w1 - w0) / (t1 - t0) * tau * tau;
      }
      if (t > time_s.back()) angle += rpm_values.back() * kRpmToRadPerS * (t - time_s.back());
      return angle;
    }
  }
  return 0.0;
}

double SpeedProfile::max_rpm() const {
  switch (kind) {
    case Kind::kConstant:
      return rpm;
    case Kind::kRamp:
      return std::max(from_rpm, to_rpm);
    case Kind::kMeasured:
      return *std::max_element(rpm_values.begin(), rpm_values.end());
  }
  return 0.0;
}

double SpeedProfile::min_rpm() const {
  switch (kind) {
    case Kind::kConstant:
      return rpm;
    case Kind::kRamp:
      return std::min(from_rpm, to_rpm);
    case Kind::kMeasured:
      return *std::min_element(rpm_values.begin(), rpm_values.end());
  }
  return 0.0;
}

}  // namespace sim
