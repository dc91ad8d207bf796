// Rolling-bearing characteristic fault frequencies from the geometry (MATLAB bearingFaultBands
// equivalent): the one implementation, used by the detectors (detect::bearing_frequencies, the
// fault bands and the bearing decision) and by the simulator's bearing model
// (sim::simulate_bearing_signal), so that both work with the same rates.
//
// Stationary outer race, inner race turning with the shaft at f_r, no slip, rigid contact
// (Randall & Antoni, "Rolling element bearing diagnostics - a tutorial", MSSP 25 (2011) 485-520,
// eqs. 1-4; Harris, "Rolling Bearing Analysis"). With n rolling elements, pitch diameter P_d,
// element diameter B_d and contact angle phi, and rho = (B_d / P_d) cos(phi):
//
//   FTF  = f_r / 2 (1 - rho)                       cage (fundamental train) frequency
//   BPFO = n f_r / 2 (1 - rho) = n FTF             ball pass frequency, outer race
//   BPFI = n f_r / 2 (1 + rho) = n (f_r - FTF)     ball pass frequency, inner race
//   BSF  = P_d f_r / (2 B_d) (1 - rho^2)           ball (roller) spin frequency
//
// The same from rolling without sliding: the ball's centre moves at the mean of the race surface
// speeds at the contacts (outer 0, inner w_r (P_d - B_d cos phi) / 2), so the cage turns at
// FTF; the ball's surface speed at the inner contact equals the inner race's speed relative to
// the cage, (f_r - FTF) (P_d - B_d cos phi) / B_d = BSF (tests/libdiag/bearing_rates_test.cpp
// checks the two derivations agree).
//
// The ball-fault line: a spall on a ball strikes the inner and the outer race once each per spin
// revolution, so its impacts repeat at 2 BSF (Randall & Antoni 2011, section 2.1: ball faults
// show mainly the even harmonics of BSF). ball_fault_hz = 2 BSF is the line the fault bands and
// the decision helper use; it is also what the CWRU bearing data centre tabulates under "BSF"
// (4.7135 x f_r for the SKF 6205-2RS JEM, whose BSF by the formula above is 2.3567 x f_r).
//
// CAUTION: real bearings slip; measured lines sit 1-2 % away from these values (Randall & Antoni
// 2011, section 2.1), so search windows must allow for it (detect/gear/fault_bands.hpp does).
#pragma once

#include <string>

#include "diag/gearbox/gearbox.hpp"

namespace diag {

struct BearingRates {
  double shaft_hz = 0;       // f_r, the inner race's rotation frequency [Hz]
  double ftf_hz = 0;         // cage (fundamental train) [Hz]
  double bpfo_hz = 0;        // outer-race defect: n FTF [Hz]
  double bpfi_hz = 0;        // inner-race defect: n (f_r - FTF) [Hz]
  double bsf_hz = 0;         // ball spin relative to the cage [Hz]
  double ball_fault_hz = 0;  // 2 BSF: ball-defect impact rate (CWRU's "BSF") [Hz]
};

// Throws InputError("where 'bearing name': field: value (valid range)") when the geometry is
// outside BearingSpec's stated ranges (n >= 3, 0 < B_d < P_d, 0 <= phi < pi/2) or shaft_hz is not
// > 0 and finite. `where` names the caller ("bearing_frequencies", "bearing signal").
BearingRates bearing_rates(const BearingSpec& bearing, double shaft_hz,
                           const std::string& where = "bearing_rates");

// The CWRU drive-end bearing, SKF 6205-2RS JEM, as the data centre gives it: 9 balls, pitch
// diameter 1.537 in = 39.04 mm, ball diameter 0.3126 in = 7.94 mm, contact angle 0 (the reference
// bearing of validate --bearings and of the bearing tests), named `name` on shaft `shaft`.
BearingSpec skf6205(std::string name = "drive_end", std::string shaft = "");

}  // namespace diag
