#include "diag/geometry/gear_pair.hpp"

#include <cmath>
#include <sstream>

#include "diag/error.hpp"
#include "diag/units.hpp"

namespace diag {

namespace {
double sq(double v) { return v * v; }
}  // namespace

double involute(double a) { return std::tan(a) - a; }

double inverse_involute(double inv) {
  if (!(inv >= 0) || !std::isfinite(inv)) {
    throw InputError(format_error("inverse_involute", "inv", "must be finite and >= 0"));
  }
  // Cheng's starting value (a ~ (3 inv)^(1/3) for small angles), then Newton on tan(a) - a - inv,
  // whose derivative is tan^2(a).
  double a = std::cbrt(3.0 * inv);
  if (a > 1.5) a = 1.5;
  for (int it = 0; it < 60 && a > 0; ++it) {
    const double t = std::tan(a);
    const double step = (t - a - inv) / (t * t);
    a -= step;
    if (std::abs(step) < 1e-15) break;
  }
  return a;
}

GearPair::GearPair(const Gear& driver, const Gear& driven, const char* where,
                   double centre_distance_m)
    : g1_(driver), g2_(driven) {
  const GearSpec& a = g1_.spec();
  const GearSpec& b = g2_.spec();
  constexpr double kRelTol = 1e-9;  // equal module / angle up to JSON round-off
  if (std::abs(a.module_m - b.module_m) > kRelTol * a.module_m) {
    std::ostringstream m;
    m << "module of driver (" << units::m_to_mm(a.module_m) << " mm) and driven ("
      << units::m_to_mm(b.module_m) << " mm) differ: the gears cannot mesh";
    throw InputError(format_error(where, "module_mm", m.str()));
  }
  if (std::abs(a.pressure_angle_rad - b.pressure_angle_rad) > kRelTol) {
    throw InputError(format_error(where, "pressure_angle_deg",
                                  "driver and driven differ: the gears cannot mesh"));
  }
  const double alpha = a.pressure_angle_rad;
  const int z1 = a.teeth, z2 = b.teeth;
  const double a0 = 0.5 * a.module_m * (z1 + z2);  // reference centre distance
  if (centre_distance_m > 0) {
    const double c = a0 * std::cos(alpha) / centre_distance_m;
    if (c >= 1.0) {
      throw InputError(
          format_error(where, "centre_distance_mm", "too small for the base circles to mesh"));
    }
    alpha_w_ = std::acos(c);
    a_w_ = centre_distance_m;
    // A distance below the zero-backlash one means the teeth would overlap.
    const double inv_w0 =
        involute(alpha) + 2.0 * std::tan(alpha) * (a.profile_shift + b.profile_shift) / (z1 + z2);
    const double a_w0 = a0 * std::cos(alpha) / std::cos(inverse_involute(inv_w0));
    if (centre_distance_m < a_w0 * (1 - 1e-9)) {
      std::ostringstream m;
      m << "must be >= the zero-backlash distance " << units::m_to_mm(a_w0) << " mm (got "
        << units::m_to_mm(centre_distance_m) << " mm)";
      throw InputError(format_error(where, "centre_distance_mm", m.str()));
    }
  } else {
    // inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2) / (z1 + z2)  (ISO 21771, zero backlash)
    const double inv_w =
        involute(alpha) + 2.0 * std::tan(alpha) * (a.profile_shift + b.profile_shift) / (z1 + z2);
    alpha_w_ = inverse_involute(inv_w);
    a_w_ = a0 * std::cos(alpha) / std::cos(alpha_w_);
  }
  const double rb1 = g1_.base_radius_m(), rb2 = g2_.base_radius_m();
  const double ra1 = g1_.tip_radius_m(), ra2 = g2_.tip_radius_m();
  const double L = loa_length_m();
  s_start_ = L - std::sqrt(ra2 * ra2 - rb2 * rb2);
  s_end_ = std::sqrt(ra1 * ra1 - rb1 * rb1);
  uncut_contact_ratio_ = (s_end_ - s_start_) / base_pitch_m();
  // A tip reaching past the mate's base-circle tangency point meets the mate below its involute.
  // On a gear that is not undercut that is the fillet: interference, the pair cannot turn. On an
  // undercut gear the rack has cut that material away (the purpose of generating cutting), so the
  // tip passes through the undercut without contact, and contact starts only where the mate's
  // usable involute begins (its form radius).
  const bool cut1 = g1_.undercut(), cut2 = g2_.undercut();
  if ((s_start_ < 0 && !cut1) || (s_end_ > L && !cut2)) {
    throw InputError(format_error(
        where, "teeth",
        "tip interference: a tip reaches past the other gear's base-circle tangency point "
        "(use a profile shift or fewer addendum)"));
  }
  if (cut1) s_start_ = std::max(s_start_, std::sqrt(sq(g1_.form_radius_m()) - rb1 * rb1));
  if (cut2) s_end_ = std::min(s_end_, L - std::sqrt(sq(g2_.form_radius_m()) - rb2 * rb2));
  // A tip that reaches the mate's root circle digs into it: the radial clearance must stay >= 0.
  constexpr double kClearanceTol = 1e-9;  // [m], round-off of the centre distance
  for (int side = 0; side < 2; ++side) {
    const Gear& tip_gear = side == 0 ? g1_ : g2_;
    const Gear& root_gear = side == 0 ? g2_ : g1_;
    const double clearance = a_w_ - tip_gear.tip_radius_m() - root_gear.root_radius_m();
    if (clearance < -kClearanceTol) {
      std::ostringstream m;
      m << "the tip of the " << (side == 0 ? "driver" : "driven")
        << " reaches into the root of the " << (side == 0 ? "driven" : "driver")
        << " (radial clearance " << units::m_to_mm(clearance)
        << " mm): lower its addendum_coefficient or profile_shift, or give a larger "
           "centre_distance_mm";
      throw InputError(format_error(where, "teeth", m.str()));
    }
  }
  if (contact_ratio() < 1.0) {
    std::ostringstream m;
    m << "contact ratio " << contact_ratio() << " < 1: the pair cannot transmit motion smoothly";
    if (cut1 || cut2) {
      m << " (undercut " << (cut1 ? "driver" : "driven") << ": " << uncut_contact_ratio_
        << " with involute flanks down to the base circle; a profile shift removes the undercut)";
    }
    throw InputError(format_error(where, "contact_ratio", m.str()));
  }
}

double GearPair::ratio() const { return static_cast<double>(g2_.teeth()) / g1_.teeth(); }
double GearPair::loa_length_m() const { return a_w_ * std::sin(alpha_w_); }
double GearPair::s_pitch_m() const { return g1_.base_radius_m() * std::tan(alpha_w_); }
double GearPair::base_pitch_m() const { return g1_.base_pitch_m(); }
double GearPair::contact_ratio() const { return path_of_contact_m() / base_pitch_m(); }
double GearPair::mesh_period_rad() const { return g1_.angular_pitch_rad(); }

ContactKinematics GearPair::kinematics(double s, double omega1) const {
  ContactKinematics k;
  const double omega2 = omega1 / ratio();
  k.s_m = s;
  k.rho1_m = s;
  k.rho2_m = loa_length_m() - s;
  k.reduced_radius_m = k.rho1_m * k.rho2_m / (k.rho1_m + k.rho2_m);
  k.v1_m_per_s = omega1 * k.rho1_m;
  k.v2_m_per_s = omega2 * k.rho2_m;
  k.sliding_m_per_s = k.v1_m_per_s - k.v2_m_per_s;
  k.rolling_sum_m_per_s = k.v1_m_per_s + k.v2_m_per_s;
  // CAUTION: lambda1 diverges at T1 (rho1 -> 0) and lambda2 at T2; within the path of contact
  // both stay finite because s_start > 0 and s_end < T1T2 (checked in the constructor).
  const double z1 = g1_.teeth(), z2 = g2_.teeth();
  k.specific_sliding_1 = 1.0 - (k.rho2_m * z1) / (k.rho1_m * z2);
  k.specific_sliding_2 = 1.0 - (k.rho1_m * z2) / (k.rho2_m * z1);
  // Seed 000 gives the arm as l = (d_b1/2) tan(phi + alpha_p1), which is rho1 only if phi is the
  // increment of the profile angle; as a function of the gear's rotation the contact moves
  // linearly along the LOA (s = s_start + r_b1 phi), so the arm is simply rho1 (and rho2 for
  // gear 2). Corrected here; see docs/physics.md, "Corrections to the sources".
  k.friction_arm_1_m = k.rho1_m;
  k.friction_arm_2_m = k.rho2_m;
  return k;
}

std::vector<double> GearPair::contacts_at(double phi1) const {
  const double theta = mesh_period_rad();
  double frac = std::fmod(phi1, theta);
  if (frac < 0) frac += theta;
  const double pb = base_pitch_m();
  // Half a nanometre: keeps a pair exactly at the end of contact from flickering through round-off.
  constexpr double kEdgeTol = 5e-10;
  std::vector<double> s;
  for (double p = s_start_ + g1_.base_radius_m() * frac; p <= s_end_ + kEdgeTol; p += pb) {
    s.push_back(p);
  }
  return s;
}

int GearPair::sliding_sign(double s) const {
  const double d = s - s_pitch_m();
  constexpr double kPitchTol = 1e-12;  // [m]
  if (std::abs(d) <= kPitchTol) return 0;
  return d < 0 ? -1 : 1;
}

}  // namespace diag
