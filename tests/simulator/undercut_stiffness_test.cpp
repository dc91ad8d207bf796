// Mesh stiffness of undercut gears: the potential-energy tooth takes its section below
// the form radius from the rack-generated profile instead of Chen & Shao's straight line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <utility>
#include <vector>

#include "diag/geometry/gear_pair.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace {

using sim::MeshStiffness;
using sim::StiffnessOptions;

diag::Gear gear(int z, double x, double m_mm = 2.0, double b_mm = 20.0) {
  diag::GearSpec s;
  s.teeth = z;
  s.module_m = m_mm * 1e-3;
  s.face_width_m = b_mm * 1e-3;
  s.profile_shift = x;
  return diag::Gear(s);
}

StiffnessOptions section(StiffnessOptions::ToothSection t) {
  StiffnessOptions o;
  o.tooth_section = t;
  return o;
}
StiffnessOptions straight_line() { return section(StiffnessOptions::ToothSection::kStraightLine); }
StiffnessOptions profile() { return section(StiffnessOptions::ToothSection::kProfile); }

// Roll distances on the usable flank: from the form radius to the tip, n points.
std::vector<double> flank_rolls(const diag::Gear& g, int n) {
  const double rb = g.base_radius_m(), rf = g.form_radius_m(), ra = g.tip_radius_m();
  const double lo = std::sqrt(rf * rf - rb * rb), hi = std::sqrt(ra * ra - rb * rb);
  std::vector<double> r;
  for (int i = 0; i < n; ++i) r.push_back(lo + (hi - lo) * (i + 0.5) / n);
  return r;
}

// Largest and smallest relative compliance excess of `o` over the straight line on the flank.
std::pair<double, double> excess(const diag::Gear& g, const StiffnessOptions& o) {
  double worst = 0, least = 1e9;
  for (double rho : flank_rolls(g, 9)) {
    const double c = sim::tooth_compliance(g, rho, o).total();
    const double c0 = sim::tooth_compliance(g, rho, straight_line()).total();
    worst = std::max(worst, c / c0 - 1);
    least = std::min(least, c / c0 - 1);
  }
  return {least, worst};
}

// Consistency without undercut: the generated section differs from Chen & Shao's straight line
// only where the rack's fillet dips inside the line h = h_b between the root and base circles
// (up to 20 um for z = 15 at x_min). Measured tooth compliance excess of the generated section:
// z = 15 at x_min 0.08..0.14 %, z = 18 0.03..0.05 %, z = 30, z = 49 (m = 4) and z = 80, x = 0.3
// below 1e-12 (the fillet stays outside the line). Bound 0.25 %: the straight line is the
// published model's approximation, this is its size for full-depth teeth. Never below -1e-10:
// the min only removes material; -2.4e-11 (z = 30) is the quadrature's round-off (96 Gauss
// panels against the straight line's one panel for the same constant section).
TEST(UndercutStiffness, WithoutUndercutTheGeneratedSectionMatchesTheStraightLine) {
  const double x_min = gear(15, 0.0).min_profile_shift_without_undercut();
  for (const diag::Gear& g :
       {gear(15, x_min), gear(18, 0.0), gear(30, 0.0), gear(49, 0.0, 4.0), gear(80, 0.3)}) {
    ASSERT_FALSE(g.undercut());
    const auto [least, worst] = excess(g, profile());
    std::cout << "z = " << g.teeth() << ", x = " << g.spec().profile_shift
              << ": generated section over straight line " << least * 100 << " .. " << worst * 100
              << " %\n";
    EXPECT_GE(least, -1e-10) << g.teeth();
    EXPECT_LT(worst, 2.5e-3) << g.teeth();
    // The default keeps the published model for a gear without undercut, bit for bit.
    for (double rho : flank_rolls(g, 3)) {
      EXPECT_EQ(sim::tooth_compliance(g, rho).total(),
                sim::tooth_compliance(g, rho, straight_line()).total());
    }
  }
}

// The undercut removes material, so every loaded point of the z = 15 tooth is more compliant
// than the straight-line model says, the more so the deeper the undercut; as x rises to x_min
// the excess falls to the generated fillet's own (the previous test's) value: the
// undercut-specific part vanishes, and the generated section is continuous across x_min.
TEST(UndercutStiffness, UndercutToothIsSofterThanTheStraightLineAndConvergesAtXmin) {
  const double x_min = gear(15, 0.0).min_profile_shift_without_undercut();
  double previous = 1e9;
  for (double x : {0.0, 0.04, 0.08, 0.11, x_min - 1e-3}) {
    const diag::Gear g = gear(15, x);
    ASSERT_TRUE(g.undercut()) << x;
    const auto [least, worst] = excess(g, {});
    std::cout << "x = " << x << ": undercut tooth compliance over the straight line " << least * 100
              << " .. " << worst * 100 << " %\n";
    EXPECT_GT(least, 0.0) << x;
    EXPECT_LT(worst, previous) << x;
    previous = worst;
  }
  // Continuity at x_min of the generated section: x_min - 1e-3 (undercut) against x_min (not),
  // flank point by flank point at the same relative roll position. The straight-line model
  // itself moves by the shift's thickening (measured below); the generated section's change must
  // be of that size, i.e. no step left by the undercut. Bound: 3 times the straight line's own
  // change over the same 1e-3 of shift.
  const diag::Gear below = gear(15, x_min - 1e-3), at = gear(15, x_min);
  const auto rb = flank_rolls(below, 9), ra = flank_rolls(at, 9);
  for (std::size_t i = 0; i < rb.size(); ++i) {
    const double step = sim::tooth_compliance(below, rb[i]).total() /
                            sim::tooth_compliance(at, ra[i], profile()).total() -
                        1;
    const double line = sim::tooth_compliance(below, rb[i], straight_line()).total() /
                            sim::tooth_compliance(at, ra[i], straight_line()).total() -
                        1;
    if (i == 4)
      std::cout << "step at x_min (mid flank): generated " << step * 100 << " %, straight line "
                << line * 100 << " %\n";
    EXPECT_LT(std::abs(step), 3 * std::abs(line) + 1e-5) << i;
  }
}

// ISO 6336-1 method B's single stiffness c' (q' with its 1/z terms, the small-pinion effect) as
// the outside reference: the undercut 15/50 pair stands to ISO as a non-undercut pair of the same
// module does (20/50, and the 15-tooth pinion shifted to x_min), while the straight-line model
// makes the undercut pair stiffer than that.
TEST(UndercutStiffness, SinglePairStiffnessAgainstIso6336LikeANonUndercutPair) {
  auto ratio = [](const diag::GearPair& p, const StiffnessOptions& o) {
    const double b = p.driver().spec().face_width_m;
    return MeshStiffness(p, o).max_pair_stiffness() / b / sim::iso6336_method_b(p).c_prime_n_per_m2;
  };
  const diag::GearPair under(gear(15, 0.0), gear(50, 0.0));
  const double x_min = gear(15, 0.0).min_profile_shift_without_undercut();
  const double r_under = ratio(under, {});
  const double r_line = ratio(under, straight_line());
  const double r_20 = ratio(diag::GearPair(gear(20, 0.0), gear(50, 0.0)), {});
  const double r_xmin = ratio(diag::GearPair(gear(15, x_min), gear(50, 0.0)), {});
  std::cout << "max single-pair stiffness / ISO c': 15/50 undercut " << r_under
            << " (straight line " << r_line << "), 20/50 " << r_20 << ", 15(x_min)/50 " << r_xmin
            << "\n";
  EXPECT_LT(r_under, r_line);
  // 15 %: the PEM-vs-ISO tolerance of Iso6336.PotentialEnergyMeanStiffness... (Cooley et al.'s
  // PEM-vs-FE spread), here between the undercut pair's ratio and the non-undercut pairs'.
  constexpr double kRelTol = 0.15;
  EXPECT_NEAR(r_under / r_20, 1.0, kRelTol);
  EXPECT_NEAR(r_under / r_xmin, 1.0, kRelTol);
  EXPECT_NEAR(r_under, 1.0, kRelTol);
}

}  // namespace
