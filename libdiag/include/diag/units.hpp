// Unit conversions, in one place. Everything inside geardiag is SI (m, rad, s, N, Pa, kg);
// these are used only at the edges (JSON descriptions, CLI options, reports).
#pragma once

#include <numbers>

namespace diag::units {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

constexpr double deg_to_rad(double deg) { return deg * kPi / 180.0; }
constexpr double rad_to_deg(double rad) { return rad * 180.0 / kPi; }
constexpr double mm_to_m(double mm) { return mm * 1e-3; }
constexpr double m_to_mm(double m) { return m * 1e3; }
constexpr double um_to_m(double um) { return um * 1e-6; }
constexpr double m_to_um(double m) { return m * 1e6; }
constexpr double rpm_to_rad_per_s(double rpm) { return rpm * kTwoPi / 60.0; }
constexpr double rad_per_s_to_rpm(double w) { return w * 60.0 / kTwoPi; }
constexpr double rpm_to_hz(double rpm) { return rpm / 60.0; }
constexpr double gpa_to_pa(double gpa) { return gpa * 1e9; }
// Brinell hardness number HB is nominally kgf/mm^2; 1 kgf = 9.80665 N.
inline constexpr double kKgf = 9.80665;
constexpr double pa_to_kgf_per_cm2(double pa) { return pa / kKgf * 1e-4; }
constexpr double hb_to_kgf_per_cm2(double hb) { return hb * 100.0; }

}  // namespace diag::units
