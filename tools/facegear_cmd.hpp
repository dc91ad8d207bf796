// The face-gear pair (seed 002) in the subcommands: simulate, sweep and info recognise a
// description with "face_gear_pair" and hand it here; `geardiag bifurcation` is its own command.
#pragma once

#include <string>

#include "diag/io/recording.hpp"
#include "sim/facegear/description.hpp"

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

// The recording `simulate` writes for a face-gear pair (dte, dte_rate, mesh torque and stiffness,
// both angles, contact state; truth with DLF, impact and period classes), from a parsed
// description; a.gearbox/output/scenario/rpm/torque are not used. gearbox_json is stored as the
// recording's /gearbox. The run's options, checked (InputError naming --duration or --fs).
diag::Recording face_gear_recording(const sim::facegear::Description& d,
                                    const std::string& gearbox_json, const FaceGearSimulateArgs& a);
sim::facegear::RunOptions face_gear_run_options(const sim::facegear::Description& d,
                                                double duration_s, double fs_hz);

struct FaceGearSweepArgs {
  std::string gearbox, scenario, json_out;
  double from_rpm = 0, to_rpm = 0;
  int steps = 40;
  bool down = false;
};
int sweep_face_gear(const FaceGearSweepArgs& a);

int info_face_gear(const std::string& gearbox, bool json);

}  // namespace geardiag
