// Gear and gear-pair geometry against numbers worked by hand (steps in the comments) and against
// the textbook relations they must satisfy.
#include <gtest/gtest.h>

#include <cmath>

#include "diag/error.hpp"
#include "diag/geometry/gear_pair.hpp"
#include "diag/units.hpp"

namespace {

using diag::Gear;
using diag::GearPair;
using diag::GearSpec;
using diag::units::deg_to_rad;

GearSpec spur(int z, double m_mm, double x = 0.0) {
  GearSpec s;
  s.teeth = z;
  s.module_m = m_mm * 1e-3;
  s.pressure_angle_rad = deg_to_rad(20.0);
  s.face_width_m = 20e-3;
  s.profile_shift = x;
  return s;
}

// Seed 000's pair: z = 49/51, m = 4 mm, alpha = 20 deg, standard (x = 0, h_a* = 1).
// By hand (ISO 21771 relations, evaluated with a calculator):
// r_b1 = 98 cos20 = 92.0899 mm, r_a1 = 102 mm, sqrt(r_a1^2 - r_b1^2) = 43.8572 mm;
// r_b2 = 102 cos20 = 95.8486 mm, r_a2 = 106 mm, sqrt(r_a2^2 - r_b2^2) = 45.2663 mm;
// a sin(alpha) = 200 sin20 = 68.4040 mm; g_alpha = 43.8572 + 45.2663 - 68.4040 = 20.7195 mm;
// p_b = pi 4 cos20 = 11.8085 mm; epsilon = 20.7195 / 11.8085 = 1.7546.
// The seed quotes 1.78: 1.4 % more than the standard basic rack gives, which fits a slightly
// longer addendum in the seed's FEM geometry (the seed does not list its tip diameters).
TEST(GearPair, ContactRatioOfTheSeedPairMatchesTheHandComputation) {
  const GearPair p(Gear(spur(49, 4)), Gear(spur(51, 4)));
  constexpr double kTol = 2e-4;  // the hand computation carries 4 decimals
  EXPECT_NEAR(p.contact_ratio(), 1.7546, kTol);
  EXPECT_NEAR(p.centre_distance_m(), 0.200, 1e-12);
  EXPECT_NEAR(p.path_of_contact_m() * 1e3, 20.7195, 1e-3);
  EXPECT_NEAR(p.contact_ratio(), 1.78, 0.03) << "the seed's quoted value";
}

// The seed-003 gearbox's pairs, z = 18 / 36, m = 3 mm, by hand: r_b1 = 25.3717 mm, r_a1 = 30,
// sqrt = 16.0086; r_b2 = 50.7434, r_a2 = 57, sqrt = 25.9636; a sin(alpha) = 81 sin20 = 27.7036;
// g = 14.2686 mm; p_b = 8.8564 mm; epsilon = 1.6111.
TEST(GearPair, ContactRatioOfTheSeed003PairMatchesTheHandComputation) {
  const GearPair p(Gear(spur(18, 3)), Gear(spur(36, 3)));
  EXPECT_NEAR(p.contact_ratio(), 1.6111, 2e-4);
}

TEST(GearPair, SlidingVanishesAndChangesSignAtThePitchPoint) {
  const GearPair p(Gear(spur(49, 4)), Gear(spur(51, 4)));
  const double w1 = 100.0;
  const double sp = p.s_pitch_m();
  ASSERT_GT(sp, p.s_start_m());
  ASSERT_LT(sp, p.s_end_m());
  EXPECT_NEAR(p.kinematics(sp, w1).sliding_m_per_s, 0.0, 1e-12);
  EXPECT_LT(p.kinematics(sp - 1e-3, w1).sliding_m_per_s, 0.0);
  EXPECT_GT(p.kinematics(sp + 1e-3, w1).sliding_m_per_s, 0.0);
  EXPECT_EQ(p.sliding_sign(sp - 1e-3), -1);
  EXPECT_EQ(p.sliding_sign(sp + 1e-3), 1);
  EXPECT_EQ(p.sliding_sign(sp), 0);
  // Sliding speed is linear in s with slope omega1 + omega2 (both radii change by ds).
  const double w2 = w1 / p.ratio();
  const auto a = p.kinematics(sp + 2e-3, w1), b = p.kinematics(sp + 5e-3, w1);
  EXPECT_NEAR((b.sliding_m_per_s - a.sliding_m_per_s) / 3e-3, w1 + w2, 1e-9);
}

// Specific sliding at the ends of the path of contact, by hand for z = 49/51, m = 4:
// at s_start: rho1 = 68.4040 - 45.2663 = 23.1377 mm, rho2 = 45.2663 mm,
//   lambda1 = 1 - rho2 z1 / (rho1 z2) = 1 - 45.2663*49 / (23.1377*51) = -0.87966,
//   lambda2 = 1 - rho1 z2 / (rho2 z1) = 1 - 23.1377*51 / (45.2663*49) = 0.46799;
// at s_end: rho1 = 43.8572, rho2 = 24.5468:
//   lambda1 = 1 - 24.5468*49 / (43.8572*51) = 0.46225, lambda2 = 1 - 43.8572*51/(24.5468*49) =
//   -0.85960.
TEST(GearPair, SpecificSlidingAtTheEndsOfContactMatchesTheHandComputation) {
  const GearPair p(Gear(spur(49, 4)), Gear(spur(51, 4)));
  constexpr double kTol = 5e-4;  // hand values carry 4 significant figures of rho
  const auto a = p.kinematics(p.s_start_m(), 1.0), e = p.kinematics(p.s_end_m(), 1.0);
  EXPECT_NEAR(a.specific_sliding_1, -0.87966, kTol);
  EXPECT_NEAR(a.specific_sliding_2, 0.46799, kTol);
  EXPECT_NEAR(e.specific_sliding_1, 0.46225, kTol);
  EXPECT_NEAR(e.specific_sliding_2, -0.85960, kTol);
  // Identity: (1 - lambda1)(1 - lambda2) = 1 everywhere.
  for (double s = p.s_start_m(); s <= p.s_end_m(); s += 1e-3) {
    const auto k = p.kinematics(s, 1.0);
    EXPECT_NEAR((1 - k.specific_sliding_1) * (1 - k.specific_sliding_2), 1.0, 1e-12);
    EXPECT_NEAR(k.friction_arm_1_m + k.friction_arm_2_m, p.loa_length_m(), 1e-15);
  }
}

TEST(GearPair, SingleAndDoubleContactZonesAddUpToOneMeshPeriod) {
  const GearPair p(Gear(spur(49, 4)), Gear(spur(51, 4)));
  const int n = 100000;
  int single = 0, twin = 0;
  for (int i = 0; i < n; ++i) {
    const double phi = p.mesh_period_rad() * (i + 0.5) / n;
    const auto c = p.contacts_at(phi);
    ASSERT_GE(c.size(), 1u);
    ASSERT_LE(c.size(), 2u);
    (c.size() == 1 ? single : twin)++;
  }
  EXPECT_EQ(single + twin, n);
  const double eps = p.contact_ratio();
  constexpr double kTol = 2.0 / 100000;  // one sample at each zone boundary
  EXPECT_NEAR(double(twin) / n, eps - 1.0, kTol);
  EXPECT_NEAR(double(single) / n, 2.0 - eps, kTol);
}

TEST(GearPair, ContactsMoveAlongTheLineOfActionByTheBaseRadiusPerRadian) {
  const GearPair p(Gear(spur(30, 2)), Gear(spur(45, 2)));
  const double dphi = 1e-3;
  const auto a = p.contacts_at(0.1), b = p.contacts_at(0.1 + dphi);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_NEAR(b[0] - a[0], p.driver().base_radius_m() * dphi, 1e-15);
}

TEST(GearPair, ProfileShiftGivesTheWorkingPressureAngleOfTheInvoluteFunction) {
  // inv(alpha_w) = inv(20 deg) + 2 tan20 (0.5 + 0.3) / (20 + 40) = 0.0149044 + 0.0097058
  // = 0.0246103 (ISO 21771 relation).
  const GearPair p(Gear(spur(20, 2, 0.5)), Gear(spur(40, 2, 0.3)));
  EXPECT_NEAR(diag::involute(p.working_pressure_angle_rad()), 0.0246103, 1e-7);
  EXPECT_NEAR(diag::inverse_involute(diag::involute(0.4)), 0.4, 1e-13);
}

TEST(Gear, UndercutIsDetectedBelowSeventeenTeethAtZeroShift) {
  EXPECT_TRUE(Gear(spur(14, 2)).undercut());
  EXPECT_FALSE(Gear(spur(18, 2)).undercut());
  EXPECT_FALSE(Gear(spur(14, 2, 0.2)).undercut());  // x_min = 1 - 14 sin^2(20)/2 = 0.18116
  EXPECT_NEAR(Gear(spur(14, 2)).min_profile_shift_without_undercut(), 0.18116, 1e-5);
}

// The usable involute of a rack-cut gear starts at the limit point of the generating line of
// action while there is no undercut: rho_Ff = r sin(alpha) - (h_a* - x) m / sin(alpha). By hand
// for z = 30, m = 2, x = 0: r = 30, rho = 30 sin20 - 2 / sin20 = 10.26060 - 5.84761 = 4.41300 mm,
// r_b = 28.19078 mm, r_Ff = hypot(28.19078, 4.41300) = 28.53409 mm.
TEST(Gear, FormRadiusWithoutUndercutIsTheLimitPoint) {
  EXPECT_NEAR(Gear(spur(30, 2)).form_radius_m() * 1e3, 28.53409, 1e-4);
}

// Undercut: the corner's trochoid cuts the involute, so the usable involute starts above the base
// circle; the cut grows as z or x fall and vanishes continuously at x_min (where the limit point
// reaches the base circle).
TEST(Gear, UndercutRaisesTheFormRadiusAndVanishesAtTheMinimumShift) {
  // Roll distance of the form circle on the involute, sqrt(r_Ff^2 - r_b^2): the length of flank
  // the undercut takes from the path of contact.
  auto rho_form = [](const Gear& g) {
    return std::sqrt(std::pow(g.form_radius_m(), 2) - std::pow(g.base_radius_m(), 2));
  };
  const Gear z10(spur(10, 2)), z14(spur(14, 2)), z17(spur(17, 2));
  EXPECT_TRUE(z10.undercut() && z14.undercut() && z17.undercut());
  EXPECT_GT(rho_form(z10), rho_form(z14));
  EXPECT_GT(rho_form(z14), rho_form(z17));
  EXPECT_GT(rho_form(z14), 0.1e-3);  // a tenth of a millimetre of a 7.2 mm involute at m = 2
  const double x_min = z14.min_profile_shift_without_undercut();
  const Gear below(spur(14, 2, x_min - 1e-3)), above(spur(14, 2, x_min + 1e-3));
  // Continuity at x_min: on both sides the form circle is within 1e-5 of the base radius (the
  // limit point moves by 1e-3 m / sin(alpha) = 5.8 um along the line of action per 1e-3 of shift,
  // i.e. by rho^2 / (2 r_b) ~ 1e-6 mm in radius).
  EXPECT_NEAR(below.form_radius_m() / below.base_radius_m(), 1.0, 1e-5);
  EXPECT_NEAR(above.form_radius_m() / above.base_radius_m(), 1.0, 1e-5);
  const Gear z14_half(spur(14, 2, 0.5 * x_min));
  EXPECT_LT(z14_half.form_radius_m(), z14.form_radius_m());
}

// A point on the involute just above r_Ff is never inside the cutter's corner path, one just
// below is: checked here with the corner's path written independently as the rack's point seen
// from the gear, (X, Y) = rotation(-phi) (x0 - r phi, y0), and the involute point's polar angle.
TEST(Gear, FormRadiusSeparatesCutFromIntactInvolute) {
  const Gear g(spur(12, 1));
  const double m = 1e-3, alpha = deg_to_rad(20.0), r = g.pitch_radius_m(), rb = g.base_radius_m();
  const double h = 1.0 * m, half = (M_PI / 2) / 12, x0 = r * half + h * std::tan(alpha);
  const double y0 = r - h;
  // Smallest distance (in polar angle) by which the corner's path passes the flank at radius R
  // inside the tooth; > 0 means the flank there is cut.
  // Over the whole turn phi in [-1, 1] rad (the implementation scans one pitch either side of
  // the corner's nearest approach), at the corner's own radius when it is within a band of R.
  auto cut_depth = [&](double radius) {
    double deepest = -1;
    for (int i = 0; i <= 400000; ++i) {
      const double phi = -1.0 + 2.0 * i / 400000;
      const double u = x0 - r * phi;
      const double px = std::cos(phi) * u + std::sin(phi) * y0;
      const double py = -std::sin(phi) * u + std::cos(phi) * y0;
      const double rc = std::hypot(px, py);
      if (std::abs(rc - radius) > 0.2 * (radius - rb) || rc <= rb) continue;
      const double psi = half + diag::involute(alpha) - diag::involute(std::acos(rb / rc));
      const double d = std::atan2(py, px) - (M_PI / 2 - psi);
      if (rc >= radius) deepest = std::max(deepest, d);
    }
    return deepest;
  };
  const double rf = g.form_radius_m();
  // Some point between r_Ff - 0.1 (r_Ff - r_b) and r_Ff is cut; nothing above r_Ff + 5 %.
  EXPECT_GT(cut_depth(rf - 0.1 * (rf - rb)), 0.0);
  EXPECT_LT(cut_depth(rf + 0.05 * (rf - rb)), 0.0);
}

// Undercut is no longer refused: a 15-tooth pinion with a 50-tooth wheel (whose tip reaches past
// T1, interference for an uncut flank) meshes, with contact from the pinion's form circle on.
TEST(GearPair, UndercutPinionMeshesWithAShorterContact) {
  const GearPair p(Gear(spur(15, 2)), Gear(spur(50, 2)));
  EXPECT_LT(p.contact_ratio(), p.uncut_contact_ratio());
  EXPECT_GT(p.contact_ratio(), 1.0);
  const double rho_f =
      std::sqrt(std::pow(p.driver().form_radius_m(), 2) - std::pow(p.driver().base_radius_m(), 2));
  EXPECT_NEAR(p.s_start_m(), rho_f, 1e-12);
  // Without undercut nothing changes.
  const GearPair q(Gear(spur(20, 2)), Gear(spur(50, 2)));
  EXPECT_DOUBLE_EQ(q.contact_ratio(), q.uncut_contact_ratio());
}

// Tip thickness, ISO 21771: z = 20, m = 2, x = 0: r_a = 22, r_b = 18.79385, cos(alpha_a) =
// 0.854266, alpha_a = 31.3213 deg, inv = 0.0618587; s / d = (pi/2) / 20 = 0.0785398,
// inv(20 deg) = 0.0149044; s_a = 44 (0.0785398 + 0.0149044 - 0.0618587) = 1.3898 mm.
TEST(Gear, TipThicknessMatchesTheHandComputationAndPointedTeethAreRefused) {
  EXPECT_NEAR(Gear(spur(20, 2)).tip_thickness_m() * 1e3, 1.3898, 2e-4);
  // A 10-tooth gear shifted by +1: the flanks cross below the tip circle.
  EXPECT_LT(Gear::tip_thickness_unchecked(spur(10, 2, 1.0)), 0.0);
  try {
    Gear g(spur(10, 2, 1.0));
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pointed"), std::string::npos) << e.what();
  }
}

TEST(GearPair, RefusesATipThatReachesTheMatesRoot) {
  GearSpec a = spur(20, 2), b = spur(40, 2);
  a.addendum_coefficient = 1.4;  // tip 1.4 m, mate's dedendum 1.25 m
  try {
    GearPair p{Gear(a), Gear(b), "meshes[0]"};
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reaches into the root"), std::string::npos) << e.what();
  }
}

TEST(GearPair, RefusesGearsOfDifferentModules) {
  try {
    GearPair p(Gear(spur(20, 2)), Gear(spur(40, 3)), "meshes[0]");
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("meshes[0]"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("module"), std::string::npos);
  }
}

}  // namespace
