// The simulator's ground truth of a recording, typed (SimulationTruth). Stored in the recording as
// JSON text (Recording::truth_json, the HDF5 dataset /truth: the file format is unchanged);
// parse_truth reads it back, strictly (a diag::InputError names the field), and to_json writes it.
//
// JSON: {"kind": "dynamic" | "kinematic" | "bearing" | "face_gear" | ...,
//        "input_speed_rpm_min", "input_speed_rpm_max", "input_torque_nm", "load_torque_nm"
//        (the operating point; each only when known),
//        "defects": [{"type" (the fault vocabulary, diag/faults/fault_kind.hpp), "gear", "shaft",
//                     "bearing", "tooth", "size_m", "depth_m", "width_fraction", "size_gear_rad",
//                     "size_output_rad", "phase_rad", "period_input_rev", "first_event_input_rad",
//                     "shaft_frequency_hz", "gears_on_shaft", "on_power_path"} (each but "type"
//                     only when it applies)],
//        ... every other key as the model wrote it (natural frequencies, integrator, meshes,
//        seeds, bearing rates, face-gear DLF and impact class, wear state, dataset labels):
//        SimulationTruth::extra}.
// Older files are read too: a dynamic truth's "faults" array (the defects under another name,
// before the truth was typed), a bearing truth's "fault" name, a face-gear truth's
// "input_speed_rpm"; the fault names' aliases ("ball", "root_crack", ...) map to the one kind.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diag/faults/fault_kind.hpp"
#include "diag/io/recording.hpp"

namespace diag {

struct TruthDefect {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  FaultKind kind = FaultKind::kNone;  // "type"
  std::string gear, shaft, bearing;   // where ("" when it does not apply)
  int tooth = -1;                     // tooth index (-1: not set)
  double size_m = kUnset;             // crack depth / chip size / spall length [m] (dynamic)
  double depth_m = kUnset;            // spall depth [m]
  double width_fraction = kUnset;     // part of the face width affected
  double size_gear_rad = kUnset;      // rotation the gear loses at the defect [rad] (kinematic)
  double size_output_rad = kUnset;    // the same seen at the output shaft [rad]
  double phase_rad = kUnset;          // defect phase in its period [rad]
  double period_input_rev = kUnset;   // recurrence period [input revolutions]
  double first_event_input_rad = kUnset;
  double shaft_frequency_hz = kUnset;  // the defective gear's shaft rate [Hz]
  std::vector<std::string> gears_on_shaft;
  std::optional<bool> on_power_path;
};

struct SimulationTruth {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::string kind;  // the model: "dynamic", "kinematic", "bearing", "face_gear", ...
  double input_speed_rpm_min = kUnset, input_speed_rpm_max = kUnset;
  double input_torque_nm = kUnset, load_torque_nm = kUnset;
  std::vector<TruthDefect> defects;
  nlohmann::json extra = nlohmann::json::object();  // every other key, as written

  // Throws InputError("where: field: reason") for a truth that is not an object, a missing or
  // non-string "kind", a typed field of the wrong type, a defect with an unknown field or a
  // fault type outside the vocabulary.
  static SimulationTruth from_json(const nlohmann::json& j, const std::string& where);
  nlohmann::json to_json() const;
};

// The recording's truth (nullopt for a measured recording: no /truth). `where` names the
// recording in errors (its file); InputError for text that is not JSON or a bad truth.
std::optional<SimulationTruth> parse_truth(const Recording& rec, const std::string& where);
std::optional<SimulationTruth> parse_truth(const std::string& truth_json, const std::string& where);

}  // namespace diag
