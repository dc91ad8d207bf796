// geardiag validate --bearings: the closed bearing-fault loop (validation/bearing_loop.hpp).
#pragma once

namespace geardiag {

// Prints the right / silent / wrong table by fault class x SNR. Exit 1 when a healthy case gives
// a finding or a fault is named as another part.
int cmd_validate_bearings(int argc, char** argv);

}  // namespace geardiag
