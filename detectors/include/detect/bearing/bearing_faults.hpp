// Rolling-bearing characteristic fault frequencies from the geometry: FTF, BPFO, BPFI, BSF and
// the ball-fault line 2 BSF, by the one implementation the simulator uses too
// (diag/gearbox/bearing_rates.hpp: the formulas, their sources and the slip caveat).
#pragma once

#include "diag/gearbox/bearing_rates.hpp"

namespace detect {

using BearingFrequencies = diag::BearingRates;

// diag::bearing_rates, errors naming "bearing_frequencies": throws diag::InputError naming the
// field when the geometry is outside BearingSpec's stated ranges (n >= 3, 0 < B_d < P_d,
// 0 <= phi < pi/2) or shaft_hz is not > 0 and finite.
BearingFrequencies bearing_frequencies(const diag::BearingSpec& bearing, double shaft_hz);

}  // namespace detect
