// Rolling-bearing characteristic fault frequencies from the geometry (MATLAB bearingFaultBands
// equivalent).
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
// The ball-fault line: a spall on a ball strikes the inner and the outer race once each per spin
// revolution, so its impacts repeat at 2 BSF (Randall & Antoni 2011, section 2.1: ball faults
// show mainly the even harmonics of BSF). ball_fault_hz = 2 BSF is the line the fault bands and the
// decision helper use; it is also what the CWRU bearing data centre tabulates under "BSF"
// (4.7135 x f_r for the SKF 6205-2RS JEM, whose BSF by the formula above is 2.3567 x f_r).
//
// CAUTION: real bearings slip; measured lines sit 1-2 % away from these values (Randall & Antoni
// 2011, section 2.1), so search windows must allow for it (fault_bands.hpp does).
#pragma once

#include "diag/gearbox/gearbox.hpp"

namespace detect {

struct BearingFrequencies {
  double shaft_hz = 0;       // f_r, the inner race's rotation frequency [Hz]
  double ftf_hz = 0;         // cage [Hz]
  double bpfo_hz = 0;        // outer-race defect [Hz]
  double bpfi_hz = 0;        // inner-race defect [Hz]
  double bsf_hz = 0;         // ball spin [Hz]
  double ball_fault_hz = 0;  // 2 BSF: ball-defect impact rate [Hz]
};

// Throws diag::InputError naming the field when the geometry is outside BearingSpec's stated
// ranges (n >= 3, 0 < B_d < P_d, 0 <= phi < pi/2) or shaft_hz is not > 0 and finite.
BearingFrequencies bearing_frequencies(const diag::BearingSpec& bearing, double shaft_hz);

}  // namespace detect
