// MeshStiffness::set_profile_gap (the gap worn flanks give every tooth pair) and the worn pair's
// separation sim::worn_profile_gap, against their definitions.
#include <gtest/gtest.h>

#include <cmath>

#include "diag/error.hpp"
#include "diag/geometry/gear.hpp"
#include "diag/geometry/gear_pair.hpp"
#include "sim/mesh/mesh_stiffness.hpp"
#include "sim/wear/wear.hpp"

namespace {

diag::GearPair pair() {
  diag::GearSpec a, b;
  a.teeth = 18;
  b.teeth = 36;
  a.module_m = b.module_m = 3e-3;
  a.face_width_m = b.face_width_m = 0.02;
  return diag::GearPair(diag::Gear(a), diag::Gear(b));
}

// A linear gap over the path of contact is reproduced at every position (the stiffness grid holds
// linear data exactly: tolerance round-off, 1e-15 m), every pair gets it whatever its teeth, and
// the force law subtracts it.
TEST(ProfileGap, EveryPairGetsTheGapAndTheForceLawSubtractsIt) {
  const diag::GearPair p = pair();
  sim::MeshStiffness k(p);
  EXPECT_FALSE(k.has_profile_gap());
  const double s0 = p.s_start_m(), s1 = p.s_end_m();
  k.set_profile_gap({s0, s1}, {10e-6, 2e-6});
  ASSERT_TRUE(k.has_profile_gap());
  for (double t : {0.0, 0.3, 0.71, 1.0}) {
    const double s = s0 + t * (s1 - s0), g = 10e-6 + t * (2e-6 - 10e-6);
    EXPECT_NEAR(k.profile_gap(s), g, 1e-15);
    EXPECT_NEAR(k.pair_gap(s, 3, 7), g, 1e-15);
    const double delta = 15e-6;
    EXPECT_NEAR(k.pair_force(s, 3, 7, delta), k.pair_stiffness(s, 3, 7) * (delta - g),
                1e-9 * k.pair_stiffness(s, 3, 7) * delta);
    EXPECT_EQ(k.pair_force(s, 3, 7, 0.5 * g), 0.0);  // the pair has not closed its gap
  }
  EXPECT_THROW(k.set_profile_gap({s0}, {0.0}), diag::InputError);
  EXPECT_THROW(k.set_profile_gap({s1, s0}, {0.0, 0.0}), diag::InputError);
  EXPECT_THROW(k.set_profile_gap({s0, s1}, {0.0, -1e-6}), diag::InputError);
}

// g(s) = h1(s) + h2(T1T2 - s): a driver worn only at s0 and a driven gear worn only at its own
// roll T1T2 - s1 separate the pair at the two ends of the path of contact.
TEST(ProfileGap, WornPairSeparationAddsBothFlanksAtTheSameContact) {
  const diag::GearPair p = pair();
  const double L = p.loa_length_m(), s0 = p.s_start_m(), s1 = p.s_end_m();
  sim::WornPair w;
  w.roll_driver_m = {s0, 0.5 * (s0 + s1), s1};
  w.depth_driver_m = {4e-6, 0, 0};
  w.roll_driven_m = {L - s1, L - 0.5 * (s0 + s1), L - s0};
  w.depth_driven_m = {3e-6, 0, 0};
  std::vector<double> s, g;
  sim::worn_profile_gap(p, w, s, g);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_DOUBLE_EQ(g[0], 4e-6);  // driver's start of contact meets the driven tip (unworn)
  EXPECT_DOUBLE_EQ(g[1], 0.0);
  EXPECT_DOUBLE_EQ(g[2], 3e-6);  // the end of contact: the driven gear's worn root
}

}  // namespace
