// The description of a synthetic dataset (`geardiag dataset SPEC.json`) and the parameters of its
// recording k, drawn from (seed, k) alone.
//
// Spec (JSON; unknown fields are refused naming the field; docs/notes/dataset.md):
//   gearbox              path, or array of paths (drawn uniformly per recording); relative to
//                        the spec's folder
//   seed                 integer >= 0
//   recordings_per_class integer >= 1 (a class may override it with `recordings`, >= 0)
//   duration_s, fs_hz    every recording's length and sampling rate
//   operating_points     {speed_rpm, torque_nm, oil_temperature_c}: each a number or [lo, hi]
//   noise_m_per_s2       accelerometer noise RMS, number or [lo, hi] (default 0)
//   accuracy_grade       ISO 1328-1 grade, integer or [lo, hi] integers (default 0: none)
//   runout_um            eccentricity of every gear, number or [lo, hi] (default 0)
//   scenario             any other scenario field (README "Scenario description") applied to
//                        every recording: friction, oil grade, bearings, sensors, integrator ...
//   classes[]            {name, recordings, faults[]}; each fault {type, gear, tooth, and the
//                        size fields of its type as numbers or [lo, hi]}; gear: a name, an array
//                        of names, or "any" (drawn per recording among the gearbox's gears);
//                        tooth: an integer, [lo, hi] or "any" (default)
//                        type wear: depth_um only, the deepest worn point of the gear's mesh
//                        (scenario faults[] type wear; no tooth)
// Ranges are drawn uniformly and rounded to 1e-4 of their unit (so that the manifest's numbers
// are the simulated ones exactly); integer ranges uniformly over the integers.
//
// Recording k: the classes in order, each `recordings` long (class-major). Its random stream is
// splitmix64 (Steele, Lea & Flood 2014) seeded from hash(seed) ^ (k + 1) * golden ratio: the
// same draws for recording k whatever the number of threads, ranks or recordings generated
// before it. The simulation's own seed (noise, pitch errors, runout phases) is drawn from it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"

namespace geardiag {

struct Range {
  double lo = 0, hi = 0;
};
struct IntRange {
  int lo = 0, hi = 0;
};

struct DatasetFault {
  std::string type;                // crack, chip, missing, spall, wear
  std::vector<std::string> gears;  // empty: any gear
  bool any_tooth = true;
  IntRange tooth;
  Range size_mm;   // crack depth_mm, chip size_mm, spall length_mm (missing: 0)
  Range depth_um;  // spall only
  bool has_position = false;
  Range position_mm;  // spall only, optional
  Range width_fraction{1, 1};
};

struct DatasetClass {
  std::string name;
  int recordings = 0;
  std::vector<DatasetFault> faults;
};

struct DatasetSpec {
  std::filesystem::path file;
  std::vector<std::string> gearbox_paths;  // as written in the spec
  std::vector<diag::Gearbox> gearboxes;
  std::uint64_t seed = 0;
  double duration_s = 1, fs_hz = 20000;
  Range speed_rpm, torque_nm;
  bool has_oil = false;
  Range oil_c;
  Range noise{0, 0};
  IntRange grade{0, 0};
  Range runout_um{0, 0};
  nlohmann::json scenario = nlohmann::json::object();  // base scenario fields
  std::vector<DatasetClass> classes;
  std::size_t total = 0;  // recordings
  std::size_t max_faults = 0;
  std::string hash;     // 16 hex digits: the spec and the gearbox descriptions' text
  nlohmann::json json;  // the spec as read
};

struct DrawnFault {
  std::string type, gear, shaft;
  int tooth = 0;
  double size_mm = 0, depth_um = 0, position_mm = 0, width_fraction = 1;
  bool has_depth = false, has_position = false;
};

struct DrawnRecording {
  std::size_t index = 0;
  std::string id;  // "<index>-<class>", the file's stem
  std::string cls;
  int gearbox = 0;
  std::uint64_t seed = 0;  // the simulation's seed
  double speed_rpm = 0, torque_nm = 0, oil_c = 0, noise = 0, runout_um = 0;
  int grade = 0;
  std::vector<DrawnFault> faults;
  nlohmann::json scenario;  // the scenario simulated (README "Scenario description")
};

// Reads and checks a spec. Throws diag::InputError naming the file and field: unknown fields,
// bad values, a fault on a gear no gearbox has, a tooth beyond a gear's teeth, a fault size the
// tooth cannot take, a sampling rate below 2.5 x the highest mesh harmonic the detectors examine
// (detect::SidebandOptions::mesh_harmonics) at the highest speed.
DatasetSpec load_dataset_spec(const std::filesystem::path& file);

DrawnRecording draw_recording(const DatasetSpec& spec, std::size_t k);

// The manifest's columns, in order, and one recording's row (flat: one value per column, null
// where a column does not apply).
std::vector<std::string> manifest_columns(const DatasetSpec& spec);
nlohmann::json manifest_row(const DatasetSpec& spec, const DrawnRecording& r);

}  // namespace geardiag
