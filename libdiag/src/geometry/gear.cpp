#include "diag/geometry/gear.hpp"

#include <cmath>
#include <sstream>

#include "diag/error.hpp"
#include "diag/units.hpp"

namespace diag {

namespace {

void require(bool ok, const std::string& where, const std::string& field, double value,
             const std::string& range) {
  if (ok) return;
  std::ostringstream msg;
  msg << "must be " << range << " (got " << value << ")";
  throw InputError(format_error(where, field, msg.str()));
}

}  // namespace

void validate(const GearSpec& s, const std::string& where) {
  require(s.teeth >= 5, where, "teeth", s.teeth, "an integer >= 5");
  require(s.module_m > 0 && std::isfinite(s.module_m), where, "module", s.module_m, "> 0");
  require(
      s.pressure_angle_rad > units::deg_to_rad(5) && s.pressure_angle_rad < units::deg_to_rad(45),
      where, "pressure_angle", units::rad_to_deg(s.pressure_angle_rad), "between 5 and 45 degrees");
  require(std::isfinite(s.profile_shift) && std::abs(s.profile_shift) <= 2.0, where,
          "profile_shift", s.profile_shift, "within [-2, 2]");
  require(s.face_width_m > 0 && std::isfinite(s.face_width_m), where, "face_width", s.face_width_m,
          "> 0");
  require(s.addendum_coefficient > 0 && s.addendum_coefficient <= 2, where, "addendum_coefficient",
          s.addendum_coefficient, "in (0, 2]");
  require(s.clearance_coefficient >= 0 && s.clearance_coefficient <= 1, where,
          "clearance_coefficient", s.clearance_coefficient, "in [0, 1]");
  const Material& m = s.material;
  require(m.youngs_modulus_pa > 0, where, "material.youngs_modulus", m.youngs_modulus_pa, "> 0");
  require(m.poisson_ratio >= 0 && m.poisson_ratio < 0.5, where, "material.poisson_ratio",
          m.poisson_ratio, "in [0, 0.5)");
  require(m.density_kg_per_m3 > 0, where, "material.density", m.density_kg_per_m3, "> 0");
  require(m.hardness_hb > 0, where, "material.hardness_hb", m.hardness_hb, "> 0");
  require(m.roughness_ra_m > 0, where, "material.roughness_ra", m.roughness_ra_m, "> 0");
  // The root circle must stay outside the centre.
  const double rf = s.module_m * (0.5 * s.teeth - s.addendum_coefficient - s.clearance_coefficient +
                                  s.profile_shift);
  require(rf > 0, where, "teeth", s.teeth, "large enough for a positive root radius");
}

Gear::Gear(const GearSpec& spec) : spec_(spec) { validate(spec_, "gear"); }

double Gear::pitch_radius_m() const { return 0.5 * spec_.module_m * spec_.teeth; }
double Gear::base_radius_m() const { return pitch_radius_m() * std::cos(spec_.pressure_angle_rad); }
double Gear::tip_radius_m() const {
  return spec_.module_m * (0.5 * spec_.teeth + spec_.addendum_coefficient + spec_.profile_shift);
}
double Gear::root_radius_m() const {
  return spec_.module_m * (0.5 * spec_.teeth - spec_.addendum_coefficient -
                           spec_.clearance_coefficient + spec_.profile_shift);
}
double Gear::base_pitch_m() const {
  return units::kPi * spec_.module_m * std::cos(spec_.pressure_angle_rad);
}
double Gear::angular_pitch_rad() const { return units::kTwoPi / spec_.teeth; }

double Gear::min_profile_shift_without_undercut() const {
  const double s = std::sin(spec_.pressure_angle_rad);
  return spec_.addendum_coefficient - 0.5 * spec_.teeth * s * s;
}

bool Gear::undercut() const {
  // A small allowance so that the textbook limit itself (e.g. z = 17 at x = 0.006) is not refused
  // through round-off.
  constexpr double kShiftTol = 1e-9;
  return spec_.profile_shift < min_profile_shift_without_undercut() - kShiftTol;
}

double Gear::disc_mass_kg() const {
  const double r = pitch_radius_m();
  return spec_.material.density_kg_per_m3 * units::kPi * r * r * spec_.face_width_m;
}

double Gear::disc_inertia_kg_m2() const {
  const double r = pitch_radius_m();
  return 0.5 * disc_mass_kg() * r * r;
}

}  // namespace diag
