#include "diag/geometry/gear.hpp"

#include <cmath>
#include <sstream>

#include "diag/error.hpp"
#include "diag/geometry/gear_pair.hpp"
#include "diag/range_check.hpp"
#include "diag/units.hpp"

namespace diag {

namespace {}  // namespace

void validate(const GearSpec& s, const std::string& where) {
  diag::require_range(s.teeth >= 5, where, "teeth", s.teeth, ">= 5");
  diag::require_range(s.module_m > 0 && std::isfinite(s.module_m), where, "module", s.module_m,
                      "> 0");
  diag::require_range(
      s.pressure_angle_rad > units::deg_to_rad(5) && s.pressure_angle_rad < units::deg_to_rad(45),
      where, "pressure_angle", units::rad_to_deg(s.pressure_angle_rad), "(5, 45) degrees");
  diag::require_range(std::isfinite(s.profile_shift) && std::abs(s.profile_shift) <= 2.0, where,
                      "profile_shift", s.profile_shift, "[-2, 2]");
  diag::require_range(s.face_width_m > 0 && std::isfinite(s.face_width_m), where, "face_width",
                      s.face_width_m, "> 0");
  diag::require_range(s.addendum_coefficient > 0 && s.addendum_coefficient <= 2, where,
                      "addendum_coefficient", s.addendum_coefficient, "(0, 2]");
  diag::require_range(s.clearance_coefficient >= 0 && s.clearance_coefficient <= 1, where,
                      "clearance_coefficient", s.clearance_coefficient, "[0, 1]");
  const Material& m = s.material;
  diag::require_range(m.youngs_modulus_pa > 0, where, "material.youngs_modulus",
                      m.youngs_modulus_pa, "> 0");
  diag::require_range(m.poisson_ratio >= 0 && m.poisson_ratio < 0.5, where,
                      "material.poisson_ratio", m.poisson_ratio, "[0, 0.5)");
  diag::require_range(m.density_kg_per_m3 > 0, where, "material.density", m.density_kg_per_m3,
                      "> 0");
  diag::require_range(m.hardness_hb > 0, where, "material.hardness_hb", m.hardness_hb, "> 0");
  diag::require_range(m.roughness_ra_m > 0, where, "material.roughness_ra", m.roughness_ra_m,
                      "> 0");
  // The root circle must stay outside the centre.
  const double rf = s.module_m * (0.5 * s.teeth - s.addendum_coefficient - s.clearance_coefficient +
                                  s.profile_shift);
  diag::require_range(rf > 0, where, "teeth", s.teeth, "large enough for a positive root radius");
  if (s.bore_diameter_m >= 0 || !std::isfinite(s.bore_diameter_m)) {
    diag::require_range(std::isfinite(s.bore_diameter_m) && s.bore_diameter_m < 2 * rf, where,
                        "bore_diameter", units::m_to_mm(s.bore_diameter_m),
                        "in [0, root diameter " + std::to_string(units::m_to_mm(2 * rf)) + " mm)");
  }
  // A pointed tooth (no tip land) cannot be made: the flanks cross below the tip circle.
  const double sa = Gear::tip_thickness_unchecked(s);
  if (!(sa > 0)) {
    std::ostringstream msg;
    msg << "gives a pointed tooth: the thickness on the tip circle is " << units::m_to_mm(sa)
        << " mm (must be > 0; lower profile_shift (" << s.profile_shift
        << ") or addendum_coefficient (" << s.addendum_coefficient << "))";
    throw InputError(format_error(where, "profile_shift", msg.str()));
  }
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

double Gear::tip_thickness_unchecked(const GearSpec& s) {
  const double r = 0.5 * s.module_m * s.teeth;
  const double rb = r * std::cos(s.pressure_angle_rad);
  const double ra = s.module_m * (0.5 * s.teeth + s.addendum_coefficient + s.profile_shift);
  if (!(ra > rb)) return 0.0;  // the whole tooth would lie inside the base circle
  const double s_over_d =
      (0.5 * units::kPi + 2.0 * s.profile_shift * std::tan(s.pressure_angle_rad)) / s.teeth;
  return 2.0 * ra * (s_over_d + involute(s.pressure_angle_rad) - involute(std::acos(rb / ra)));
}

double Gear::tip_thickness_m() const { return tip_thickness_unchecked(spec_); }

double Gear::form_radius_m() const {
  const double m = spec_.module_m, alpha = spec_.pressure_angle_rad, x = spec_.profile_shift;
  const double r = pitch_radius_m(), rb = base_radius_m(), ra = tip_radius_m();
  const double h = (spec_.addendum_coefficient - x) * m;  // corner below the rolling line
  const double sin_a = std::sin(alpha), tan_a = std::tan(alpha);
  const double rho_limit = r * sin_a - h / sin_a;
  if (rho_limit >= 0) return std::hypot(rb, rho_limit);
  // Gear frame: tooth centred on +y, rolling line y = r touching the pitch circle at (0, r) when
  // the gear angle phi = 0. The gear turns by phi (counter-clockwise), the rack moves by -r phi;
  // the corner of the cutter tooth right of the gear tooth starts at (x0, y0) and is seen from
  // the gear at R(-phi) (x0 - r phi, y0). The gear tooth's right flank at radius R lies at polar
  // angle pi/2 - psi(R), psi(R) = s / d + inv(alpha) - inv(alpha_R) its half angle.
  const double half_pitch_angle = (0.5 * units::kPi + 2.0 * x * tan_a) / spec_.teeth;
  const double x0 = r * half_pitch_angle + h * tan_a, y0 = r - h;
  const double inv_alpha = involute(alpha);
  // The corner is nearest the centre at phi = x0 / r; it passes the tooth's flank within a
  // pitch of that. 20000 steps resolve r_Ff to ~1e-4 of the pitch radius.
  const double phi_lo = x0 / r - angular_pitch_rad(), phi_hi = x0 / r + angular_pitch_rad();
  constexpr int kSteps = 20000;
  double r_form = rb;
  for (int i = 0; i <= kSteps; ++i) {
    const double phi = phi_lo + (phi_hi - phi_lo) * i / kSteps;
    const double u = x0 - r * phi;
    const double gx = std::cos(phi) * u + std::sin(phi) * y0;
    const double gy = -std::sin(phi) * u + std::cos(phi) * y0;
    const double radius = std::hypot(gx, gy);
    if (radius <= rb || radius >= ra || radius <= r_form) continue;
    const double psi = half_pitch_angle + inv_alpha - involute(std::acos(rb / radius));
    const double theta = std::atan2(gy, gx);
    if (theta > 0.5 * units::kPi - psi && theta < 0.5 * units::kPi + psi) r_form = radius;
  }
  return r_form;
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
