// The bearing rates (diag/gearbox/bearing_rates.hpp) against a second derivation of the same
// kinematics (rolling without sliding, as the simulator's bearing model describes its contacts),
// the CWRU data centre's table (a hand-computed angular-contact bearing: tests/detectors/
// bearing_faults_test.cpp).
#include "diag/gearbox/bearing_rates.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "diag/error.hpp"

namespace {

diag::BearingSpec skf6205() { return diag::skf6205("de"); }

// Rolling without sliding: the ball's centre moves at the mean of the race surface speeds at the
// contacts (outer 0, inner w_r (P_d - B_d cos phi) / 2), so the cage turns at
// f_c = f_r (1 - rho) / 2; the ball's surface speed at the inner contact equals the inner race's
// speed relative to the cage, which gives the spin f_s = (f_r - f_c) (P_d - B_d cos phi) / B_d.
// The closed forms must agree to round-off (1e-12 of f_r: a few ulps of the products), and with
// the CWRU table (cage 0.39828, ball fault "BSF" 4.7135 x f_r) to its 5 printed digits.
TEST(BearingRates, AgreeWithRollingWithoutSlidingAndTheCwruTable) {
  constexpr double kRoundOff = 1e-12;
  constexpr double kTableRelTol = 1e-4;
  for (double phi : {0.0, 0.3}) {
    diag::BearingSpec b = skf6205();
    b.contact_angle_rad = phi;
    for (double fr : {1.0, 29.95, 173.3}) {
      const diag::BearingRates r = diag::bearing_rates(b, fr);
      const double cos_phi = std::cos(phi);
      const double fc = 0.5 * fr * (1 - b.element_diameter_m / b.pitch_diameter_m * cos_phi);
      const double fs =
          (fr - fc) * (b.pitch_diameter_m - b.element_diameter_m * cos_phi) / b.element_diameter_m;
      EXPECT_NEAR(r.shaft_hz, fr, 0.0);
      EXPECT_NEAR(r.ftf_hz, fc, kRoundOff * fr);
      EXPECT_NEAR(r.bpfo_hz, 9 * fc, kRoundOff * fr);
      EXPECT_NEAR(r.bpfi_hz, 9 * (fr - fc), kRoundOff * fr);
      EXPECT_NEAR(r.bsf_hz, fs, kRoundOff * fr);
      EXPECT_NEAR(r.ball_fault_hz, 2 * fs, kRoundOff * fr);
    }
  }
  const diag::BearingRates r = diag::bearing_rates(skf6205(), 1.0);
  EXPECT_NEAR(r.ball_fault_hz, 4.7135, 4.7135 * kTableRelTol);
  EXPECT_NEAR(r.ftf_hz, 0.39828, 0.39828 * kTableRelTol);
}

TEST(BearingRates, RejectImpossibleGeometryNamingTheCallerAndTheField) {
  diag::BearingSpec b = skf6205();
  b.rolling_elements = 2;
  try {
    diag::bearing_rates(b, 30, "bearing signal");
    ADD_FAILURE() << "no throw";
  } catch (const diag::InputError& e) {
    EXPECT_EQ(std::string(e.what()), "bearing signal 'de': rolling_elements: 2 (valid >= 3)");
  }
  EXPECT_THROW(diag::bearing_rates(skf6205(), std::nan(""), "x"), diag::InputError);
}

}  // namespace
