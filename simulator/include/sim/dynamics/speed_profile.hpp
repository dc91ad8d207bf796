// The input shaft's speed over time: constant, a linear ramp (run-up or coast-down), or a measured
// profile (piecewise linear between given points). The speed-controlled motor follows it exactly;
// the shaft angle is its integral, in closed form (piecewise quadratic).
#pragma once

#include <string>
#include <vector>

namespace sim {

struct SpeedProfile {
  enum class Kind {
    kConstant,  // rpm
    kRamp,      // from_rpm until start_s, linear to to_rpm over duration_s, then to_rpm
    kMeasured,  // (time_s[i], rpm_values[i]) piecewise linear, held constant outside
  };
  Kind kind = Kind::kConstant;
  double rpm = 0.0;                // constant speed [rpm], > 0
  double from_rpm = 0.0;           // ramp start speed [rpm], > 0
  double to_rpm = 0.0;             // ramp end speed [rpm], > 0
  double start_s = 0.0;            // ramp start time [s], >= 0
  double duration_s = 0.0;         // ramp duration [s], > 0
  std::vector<double> time_s;      // measured: strictly increasing, time_s[0] = 0
  std::vector<double> rpm_values;  // measured: > 0, same length, >= 2 points

  static SpeedProfile constant(double rpm);
  static SpeedProfile ramp(double from_rpm, double to_rpm, double start_s, double duration_s);

  void validate(const std::string& where) const;     // throws diag::InputError naming the field
  double speed_rad_per_s(double t_s) const;          // omega(t)
  double acceleration_rad_per_s2(double t_s) const;  // omega'(t) (piecewise constant)
  double angle_rad(double t_s) const;                // integral of omega from 0 to t
  double max_rpm() const;
  double min_rpm() const;
};

}  // namespace sim
