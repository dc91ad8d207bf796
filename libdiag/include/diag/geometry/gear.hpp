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
  // Bore (hole for the shaft) diameter [m]; < 0: not given, and the mesh stiffness model takes
  // its default, half the root diameter (sim::StiffnessOptions::bore_radius_ratio = 0.5); 0: a
  // solid disc; otherwise 0 <= bore < root diameter. It sets the rim under the teeth, whose
  // compliance (Sainsot et al. 2004) is about half of a tooth's.
  double bore_diameter_m = -1.0;
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
  // Undercut (x < x_min) is not an error: the rack cuts into the involute near the base circle,
  // so the usable involute starts higher (form_radius_m) and a mate's contact there is lost (a
  // lower contact ratio, see GearPair), and the tooth root is thinner than the involute model's.
  bool undercut() const;
  // Tooth thickness (arc) on the tip circle (ISO 21771, thickness on any circle, at d_a):
  //     s_a = d_a (s / d + inv(alpha) - inv(alpha_a)),  s / d = (pi / 2 + 2 x tan(alpha)) / z,
  // cos(alpha_a) = r_b / r_a. s_a <= 0 is a pointed tooth: validate() refuses it.
  double tip_thickness_m() const;
  // Radius where the usable involute begins (the generated root form radius r_Ff) for a gear cut
  // by its basic rack, modelled with the sharp corner where the cutter's straight flank ends,
  // (h_a* - x) m below the rolling line (the model behind x_min). Without undercut the corner
  // runs through the limit point on the generating line of action, at roll distance
  //     rho_Ff = r sin(alpha) - (h_a* - x) m / sin(alpha)  (>= 0);
  // with undercut the corner's trochoid cuts the involute, and r_Ff is the largest radius at
  // which the corner's path enters the tooth (found numerically). CAUTION: a cutter with a
  // rounded tip cuts slightly deeper than its corner; this model gives the upper bound of the
  // usable involute.
  double form_radius_m() const;
  // Disc approximation used by dynamics: mass and polar moment of a solid cylinder of the pitch
  // radius and the face width [kg], [kg m^2].
  double disc_mass_kg() const;
  double disc_inertia_kg_m2() const;

  // tip_thickness_m() of a spec that validate() has not (yet) accepted; 0 when r_a <= r_b.
  static double tip_thickness_unchecked(const GearSpec& spec);

 private:
  GearSpec spec_;
};

}  // namespace diag
