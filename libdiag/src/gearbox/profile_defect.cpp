#include "diag/gearbox/profile_defect.hpp"

#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "diag/geometry/profile.hpp"

namespace diag {

double profile_defect_loss_rad(const Gearbox& gb, int gear, const nlohmann::json& profile,
                               const std::string& where, const std::string& path) {
  for (const Mesh& m : gb.meshes()) {
    if (m.driver != gear && m.driven != gear) continue;
    const bool on_driver = m.driver == gear;
    const Gear& g = on_driver ? m.pair.driver() : m.pair.driven();
    const Flank flank = generate_tooth(g).flank;
    const ProfileDefect d = parse_profile_defect(profile, g, flank, where, path);
    const double loss = defect_angular_loss_rad(m.pair, on_driver, d);
    // Below a nanoradian the deviation is bridged by the mate (or lies where no contact occurs).
    constexpr double kNoLossRad = 1e-9;
    if (!(loss > kNoLossRad)) {
      throw InputError(format_error(where, path,
                                    "the mate rolls over this deviation without losing contact "
                                    "(it opens no angular loss): it is no kinematic defect"));
    }
    return loss;
  }
  throw InputError(format_error(where, path, "the gear is in no mesh: nothing rolls over it"));
}

}  // namespace diag
