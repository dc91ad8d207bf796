// The face-gear pair (seed 002) in the subcommands: simulate, sweep and info recognise a
// description with "face_gear_pair" and hand it here; `geardiag bifurcation` is its own command.
#pragma once

#include <string>

namespace geardiag {

// True when the description file is a face-gear pair (reads the JSON; InputError when unreadable).
bool is_face_gear_description(const std::string& path);
// The same for description text (e.g. a recording's /gearbox); `where` names it in errors.
bool is_face_gear_text(const std::string& json_text, const std::string& where);

struct FaceGearSimulateArgs {
  std::string gearbox, output, scenario;
  double duration_s = 1.0, fs_hz = 20000.0;
  double rpm = 0.0, torque_nm = -1.0;  // overrides when > 0 / >= 0
};
int simulate_face_gear(const FaceGearSimulateArgs& a);

struct FaceGearSweepArgs {
  std::string gearbox, scenario, json_out;
  double from_rpm = 0, to_rpm = 0;
  int steps = 40;
  bool down = false;
};
int sweep_face_gear(const FaceGearSweepArgs& a);

int info_face_gear(const std::string& gearbox, bool json);

}  // namespace geardiag
