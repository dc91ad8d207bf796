#include "sim/mesh/profile_fault.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "diag/geometry/profile.hpp"

namespace sim {

ToothFault profile_fault(const diag::GearPair& pair, bool on_driver, int tooth,
                         const nlohmann::json& profile, const std::string& where) {
  const diag::Gear& g = on_driver ? pair.driver() : pair.driven();
  const diag::Flank flank = diag::generate_tooth(g).flank;
  const diag::ProfileDefect d = diag::parse_profile_defect(profile, g, flank, where, "profile");
  const double rb = g.base_radius_m();
  auto roll = [&](double r) { return std::sqrt(std::max(0.0, r * r - rb * rb)); };
  double lo = 0, hi = 0;  // roll distances on the defective flank
  switch (d.kind) {
    case diag::ProfileDefect::Kind::kChip:
    case diag::ProfileDefect::Kind::kPit:
      lo = rb * d.roll_start_rad;
      hi = rb * d.roll_end_rad;
      break;
    case diag::ProfileDefect::Kind::kBrokenTip:
      lo = roll(d.break_radius_m);
      hi = roll(flank.top_radius_m());
      break;
    case diag::ProfileDefect::Kind::kContour:
      lo = roll(std::hypot(d.contour_m.front()[0], d.contour_m.front()[1]));
      hi = roll(std::hypot(d.contour_m.back()[0], d.contour_m.back()[1]));
      break;
  }
  const double L = pair.loa_length_m();
  double s0 = on_driver ? lo : L - hi, s1 = on_driver ? hi : L - lo;
  s0 = std::max(s0, pair.s_start_m());
  s1 = std::min(s1, pair.s_end_m());
  if (!(s1 > s0)) {
    throw diag::InputError(
        diag::format_error(where, "profile", "lies outside the path of contact: no pair meets it"));
  }
  const double loss = diag::defect_angular_loss_rad(pair, on_driver, d);
  constexpr double kNoLossRad = 1e-9;  // as in diag::profile_defect_loss_rad
  if (!(loss > kNoLossRad)) {
    throw diag::InputError(diag::format_error(
        where, "profile", "the mate rolls over this deviation without losing contact"));
  }
  ToothFault f;
  f.kind = ToothFault::Kind::kSpall;
  f.gear = on_driver ? 0 : 1;
  f.tooth = tooth;
  f.size_m = s1 - s0;
  f.s_center_m = 0.5 * (s0 + s1);
  f.depth_m = loss * rb;
  f.width_fraction = 1.0;
  return f;
}

}  // namespace sim
