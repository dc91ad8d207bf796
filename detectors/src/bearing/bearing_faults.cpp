#include "detect/bearing/bearing_faults.hpp"

namespace detect {

BearingFrequencies bearing_frequencies(const diag::BearingSpec& b, double shaft_hz) {
  return diag::bearing_rates(b, shaft_hz, "bearing_frequencies");
}

}  // namespace detect
