// bearing_rates (diag/gearbox/bearing_rates.hpp).
#include "diag/gearbox/bearing_rates.hpp"

#include <cmath>
#include <numbers>
#include <utility>

#include "diag/error.hpp"
#include "diag/range_check.hpp"

namespace diag {

BearingRates bearing_rates(const BearingSpec& b, double shaft_hz, const std::string& where) {
  const std::string who = where + (b.name.empty() ? std::string() : " '" + b.name + "'");
  if (b.rolling_elements < 3) fail_range(who, "rolling_elements", b.rolling_elements, ">= 3");
  if (!(b.pitch_diameter_m > 0) || !std::isfinite(b.pitch_diameter_m))
    fail_range(who, "pitch_diameter_m", b.pitch_diameter_m, "> 0");
  if (!(b.element_diameter_m > 0 && b.element_diameter_m < b.pitch_diameter_m))
    fail_range(who, "element_diameter_m", b.element_diameter_m, "0 < B_d < pitch_diameter_m");
  if (!(b.contact_angle_rad >= 0 && b.contact_angle_rad < std::numbers::pi / 2))
    fail_range(who, "contact_angle_rad", b.contact_angle_rad, "[0, pi/2)");
  if (!(shaft_hz > 0) || !std::isfinite(shaft_hz)) fail_range(who, "shaft_hz", shaft_hz, "> 0");

  const double rho = b.element_diameter_m / b.pitch_diameter_m * std::cos(b.contact_angle_rad);
  const double n = b.rolling_elements;
  BearingRates f;
  f.shaft_hz = shaft_hz;
  f.ftf_hz = 0.5 * shaft_hz * (1.0 - rho);
  f.bpfo_hz = n * f.ftf_hz;
  f.bpfi_hz = 0.5 * n * shaft_hz * (1.0 + rho);
  f.bsf_hz = 0.5 * shaft_hz * b.pitch_diameter_m / b.element_diameter_m * (1.0 - rho * rho);
  f.ball_fault_hz = 2.0 * f.bsf_hz;
  return f;
}

BearingSpec skf6205(std::string name, std::string shaft) {
  BearingSpec b;
  b.name = std::move(name);
  b.shaft = std::move(shaft);
  b.rolling_elements = 9;
  b.pitch_diameter_m = 39.04e-3;
  b.element_diameter_m = 7.94e-3;
  b.contact_angle_rad = 0.0;
  return b;
}

}  // namespace diag
