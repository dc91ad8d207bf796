// A flank deviation (diag::ProfileDefect, the JSON of diag::parse_profile_defect) as a tooth fault
// of the dynamic model: the deviation's roll range, mapped to the line of action (rho1 = s on the
// driver, rho2 = T1T2 - s on the driven gear) and clipped to the path of contact, becomes a
// full-width spall (ToothFault::kSpall) whose gap is the lag that unloaded rolling gives,
// loss x r_b of the defective gear (diag::defect_angular_loss_rad). CAUTION: the gap is constant
// over the range (the deepest lag), so a bell-shaped pit enters at its worst everywhere; the
// rolling's own lag curve would be the finer model.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "diag/geometry/gear_pair.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace sim {

// Throws diag::InputError naming `where` when the deviation is malformed, lies outside the path of
// contact or opens no lag.
ToothFault profile_fault(const diag::GearPair& pair, bool on_driver, int tooth,
                         const nlohmann::json& profile, const std::string& where);

}  // namespace sim
