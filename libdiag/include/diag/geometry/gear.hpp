// Involute external spur gear: geometry from the basic rack (GOST 13755 / ISO 53: alpha = 20 deg,
// h_a* = 1, c* = 0.25 by default). All lengths in metres, angles in radians.
#pragma once

#include <string>

namespace diag {

struct Material {
  double youngs_modulus_pa = 206e9;   // E [Pa], > 0 (steel)
  double poisson_ratio = 0.3;         // nu [-], 0 <= nu < 0.5
  double density_kg_per_m3 = 7850.0;  // [kg/m^3], > 0
  double hardness_hb = 300.0;         // Brinell hardness [HB, kgf/mm^2], > 0
  double roughness_ra_m = 0.8e-6;     // arithmetic mean roughness Ra [m], > 0
};

struct GearSpec {
  int teeth = 0;                                   // z, >= 5
  double module_m = 0.0;                           // m [m], > 0
  double pressure_angle_rad = 0.3490658503988659;  // alpha of the basic rack [rad], (0, pi/4)
  double profile_shift = 0.0;                      // x [-] (positive away from the centre)
  double face_width_m = 0.0;                       // b [m], > 0
  double addendum_coefficient = 1.0;               // h_a* [-]
  double clearance_coefficient = 0.25;             // c* [-]; dedendum h_f* = h_a* + c*
  Material material;
};

// Throws InputError naming `where` and the field when a value is out of range.
void validate(const GearSpec& spec, const std::string& where);

class Gear {
 public:
  explicit Gear(const GearSpec& spec);  // validates

  const GearSpec& spec() const { return spec_; }
  int teeth() const { return spec_.teeth; }
  double module_m() const { return spec_.module_m; }
  double pitch_radius_m() const;     // r = m z / 2
  double base_radius_m() const;      // r_b = r cos(alpha)
  double tip_radius_m() const;       // r_a = m (z/2 + h_a* + x)   (no tip shortening)
  double root_radius_m() const;      // r_f = m (z/2 - h_a* - c* + x)
  double base_pitch_m() const;       // p_b = pi m cos(alpha)
  double angular_pitch_rad() const;  // 2 pi / z
  // Smallest profile shift without undercut by the rack: x_min = h_a* - z sin^2(alpha) / 2.
  double min_profile_shift_without_undercut() const;
  bool undercut() const;
  // Disc approximation used by dynamics: mass and polar moment of a solid cylinder of the pitch
  // radius and the face width [kg], [kg m^2].
  double disc_mass_kg() const;
  double disc_inertia_kg_m2() const;

 private:
  GearSpec spec_;
};

}  // namespace diag
