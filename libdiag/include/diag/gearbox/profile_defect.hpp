// A gearbox defect given as a flank deviation (defects[i].profile, docs/formats.md,
// docs/profiles.md): the seed-003 route from a drawn contour to the angle the kinematic simulator
// uses. The deviation is put on one tooth of the gear, the gear's mate in the first mesh of the
// description that holds the gear rolls over it unloaded (diag::defect_angular_loss_rad), and the
// largest lag it opens, as a rotation of the defective gear, is the defect's size.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "diag/gearbox/gearbox.hpp"

namespace diag {

// Throws InputError naming `where` and `path` (e.g. "defects[0].profile") when the deviation is
// malformed, leaves the tooth, the gear is in no mesh, or the deviation opens no lag at all (a
// deviation the mate bridges over is no defect for the kinematic model).
double profile_defect_loss_rad(const Gearbox& gb, int gear, const nlohmann::json& profile,
                               const std::string& where, const std::string& path);

}  // namespace diag
