// External spur gear pair (driver 1, driven 2): working geometry, path of contact, and the
// kinematics of a contact point on the line of action (LOA).
//
// Positions on the LOA are measured by s [m] from T1, the point where the LOA touches gear 1's
// base circle, towards T2. Contact runs from s_start (gear 2's tip meets gear 1's flank) to s_end
// (gear 1's tip). The pitch point is at s_pitch = r_b1 tan(alpha_w).
//
// Formulas: ISO 21771 / Litvin & Fuentes, "Gear Geometry and Applied Theory" (2004), ch. 10;
// specific sliding as in seed 004 (docs/physics.md).
#pragma once

#include <vector>

#include "diag/geometry/gear.hpp"

namespace diag {

// inv(a) = tan(a) - a, and its inverse on [0, pi/2) by Newton iteration (|error| < 1e-14 rad).
double involute(double angle_rad);
double inverse_involute(double inv);

struct ContactKinematics {
  double s_m = 0;                  // position on the LOA from T1 [m]
  double rho1_m = 0;               // radius of curvature of gear 1's flank [m] (= s)
  double rho2_m = 0;               // radius of curvature of gear 2's flank [m]
  double reduced_radius_m = 0;     // rho1 rho2 / (rho1 + rho2) [m]
  double v1_m_per_s = 0;           // tangential speed of gear 1's surface at the contact [m/s]
  double v2_m_per_s = 0;           // same for gear 2 [m/s]
  double sliding_m_per_s = 0;      // v_s = v1 - v2: < 0 in the approach, > 0 in the recess [m/s]
  double rolling_sum_m_per_s = 0;  // V_sum = v1 + v2 [m/s]
  double specific_sliding_1 = 0;   // lambda1 = (v1 - v2) / v1 = 1 - rho2 z1 / (rho1 z2)
  double specific_sliding_2 = 0;   // lambda2 = (v2 - v1) / v2 = 1 - rho1 z2 / (rho2 z1)
  double friction_arm_1_m = 0;     // arm of the friction force about gear 1's centre: rho1 [m]
  double friction_arm_2_m = 0;     // same about gear 2's centre: rho2 [m]
};

class GearPair {
 public:
  // Centre distance from the profile shifts (zero-backlash working distance) unless
  // centre_distance_m > 0 is given. Throws InputError naming `where` when the pair cannot mesh
  // (different modules or pressure angles, contact ratio < 1, tip interference with a gear that
  // is not undercut, a tip reaching the mate's root circle). On an undercut gear (rack-generated)
  // contact starts at its form radius (Gear::form_radius_m): the path of contact is shortened.
  GearPair(const Gear& driver, const Gear& driven, const char* where = "gear pair",
           double centre_distance_m = 0.0);

  const Gear& driver() const { return g1_; }
  const Gear& driven() const { return g2_; }
  double ratio() const;  // u = z2 / z1
  double centre_distance_m() const { return a_w_; }
  double working_pressure_angle_rad() const { return alpha_w_; }
  double loa_length_m() const;  // T1T2 = a_w sin(alpha_w)
  double s_start_m() const { return s_start_; }
  double s_end_m() const { return s_end_; }
  double s_pitch_m() const;
  double path_of_contact_m() const { return s_end_ - s_start_; }  // g_alpha
  double base_pitch_m() const;
  double contact_ratio() const;  // epsilon_alpha = g_alpha / p_b
  // The contact ratio if both flanks were involute down to the base circle: differs from
  // contact_ratio() only when an undercut gear loses contact below its form radius.
  double uncut_contact_ratio() const { return uncut_contact_ratio_; }
  double mesh_period_rad() const;  // rotation of gear 1 per tooth: 2 pi / z1

  // Kinematics at LOA position s for driver speed omega1 [rad/s] (gear 2 turns at omega1 / u).
  ContactKinematics kinematics(double s_m, double omega1_rad_per_s) const;

  // The LOA positions of every tooth pair in contact when gear 1 has turned phi1 [rad] from the
  // moment a pair enters contact at s_start. The contact moves along the LOA by r_b1 dphi1.
  // Positions are listed in increasing order (the pair that entered first is last).
  std::vector<double> contacts_at(double phi1_rad) const;

  // Sign of the sliding velocity of gear 1's surface relative to gear 2's at s: -1 in the
  // approach (s < s_pitch, gear 2 slides faster), +1 in the recess, 0 at the pitch point.
  int sliding_sign(double s_m) const;

 private:
  Gear g1_, g2_;
  double alpha_w_ = 0, a_w_ = 0, s_start_ = 0, s_end_ = 0, uncut_contact_ratio_ = 0;
};

}  // namespace diag
