// geardiag demo: the built-in example, end to end, printing only what it computed.
// Today: the three-shaft gearbox of seed 003 with its two defects (1 deg on z2 at 10 deg, 1 deg on
// z4 at 5 deg), simulated kinematically with runout, mesh TE, noise and a 16-bit encoder, then
// attributed from the angles alone; the attribution table is printed next to the truth.
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "detect/attribution/period_matcher.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/units.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace geardiag {

namespace {

constexpr const char* kDemoGearbox = R"({
  "name": "seed-003 three-shaft gearbox",
  "shafts": [{"name": "input"}, {"name": "counter"}, {"name": "output"}],
  "gears": [{"name": "z1", "shaft": "input",   "teeth": 18, "module_mm": 3.0, "face_width_mm": 20.0},
            {"name": "z2", "shaft": "counter", "teeth": 36, "module_mm": 3.0, "face_width_mm": 20.0},
            {"name": "z3", "shaft": "counter", "teeth": 18, "module_mm": 3.0, "face_width_mm": 20.0},
            {"name": "z4", "shaft": "output",  "teeth": 36, "module_mm": 3.0, "face_width_mm": 20.0}],
  "meshes": [{"driver": "z1", "driven": "z2"}, {"driver": "z3", "driven": "z4"}],
  "input": {"shaft": "input", "speed_rpm": 30.0, "torque_nm": 50.0},
  "defects": [{"gear": "z2", "type": "chip", "size_deg": 1.0, "phase_deg": 10.0},
              {"gear": "z4", "type": "chip", "size_deg": 1.0, "phase_deg": 5.0}]
})";

}  // namespace

int cmd_demo(int argc, char** argv) {
  (void)argc;
  (void)argv;
  using diag::units::deg_to_rad;
  using diag::units::rad_to_deg;
  const diag::Gearbox gb = diag::parse_gearbox_text(kDemoGearbox, "built-in demo gearbox");
  std::cout << "== geardiag demo: defect attribution (seed 003) ==\n\n" << diag::format_summary(gb);

  sim::KinematicOptions k;
  k.step_rad = deg_to_rad(0.05);
  k.runout_output_rad = deg_to_rad(0.05);
  k.mesh_te_output_rad = deg_to_rad(0.005);
  k.noise_output_rad = deg_to_rad(0.002);
  k.encoder_counts_per_rev = 1 << 16;
  k.seed = 2012;
  const sim::KinematicResult r = sim::simulate_kinematic(gb, k);
  std::cout << "\nsimulated (kinematic): " << r.input_angle_rad.size() << " samples, step 0.05 deg, "
            << r.truth["revolutions"].get<double>()
            << " input revolutions; runout 0.05 deg, mesh TE 0.005 deg, noise 0.002 deg RMS, "
               "16-bit encoders\n\n";

  const detect::AttributionResult a =
      detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gb, {});
  std::cout << "attribution from the two shaft angles:\n" << detect::format_table(a);
  std::cout << "\ntruth:\n";
  for (const auto& d : r.truth["defects"]) {
    std::cout << "  " << d["gear"].get<std::string>() << " on shaft '"
              << d["shaft"].get<std::string>() << "': size " << rad_to_deg(d["size_gear_rad"].get<double>())
              << " deg at the gear = " << rad_to_deg(d["size_output_rad"].get<double>())
              << " deg at the output, every " << 360.0 * d["period_input_rev"].get<double>()
              << " deg of input, first at " << rad_to_deg(d["first_event_input_rad"].get<double>())
              << " deg\n";
  }
  std::cout << "\n(the dynamic simulator, vibration detectors and HTML report are not built yet)\n";
  return 0;
}

}  // namespace geardiag
