// The description of a synthetic dataset (`geardiag dataset SPEC.json`) and the parameters of its
// recording k, drawn from (seed, k) alone.
//
// Spec (JSON; unknown fields are refused naming the field; docs/cli/dataset.md):
//   gearbox              path, or array of paths (drawn uniformly per recording); relative to
//                        the spec's folder
//   seed                 integer >= 0
//   recordings_per_class integer >= 1 (a class may override it with `recordings`, >= 0)
//   duration_s, fs_hz    every recording's length and sampling rate
//   operating_points     {speed_rpm, torque_nm, oil_temperature_c}: each a number or [lo, hi]
//   noise_m_per_s2       accelerometer noise RMS, number or [lo, hi] (default 0)
//   accuracy_grade       ISO 1328-1 grade, integer or [lo, hi] integers (default 0: none)
//   runout_um            eccentricity of every gear, number or [lo, hi] (default 0)
//   scenario             any other scenario field (docs/formats.md, "Scenario") applied to
//                        every recording: friction, oil grade, bearings, sensors, integrator ...
//   classes[]            {name, recordings, faults[]}; each fault {type, gear, tooth, and the
//                        size fields of its type as numbers or [lo, hi]}; gear: a name, an array
//                        of names, or "any" (drawn per recording among the gearbox's gears);
//                        tooth: an integer, [lo, hi] or "any" (default)
//                        type wear: depth_um only, the deepest worn point of the gear's mesh
//                        (scenario faults[] type wear; no tooth)
//                        type bearing: {bearing, fault, amplitude_m_per_s2, resonance_hz}:
//                        bearing a name, array or "any" (the gearbox's bearings named as the
//                        simulator's bearing locations, <shaft>_bearing1|2); fault outer_race,
//                        inner_race, rolling_element, an array of them or "any" (the three)
//   simulator            "dynamic" (default: the fields above), "kinematic" (seed 003) or
//                        "face_gear" (seed 002; implied by a face-gear gearbox): their fields in
//                        tools/dataset_modes.hpp
// Ranges are drawn uniformly and rounded to 1e-4 of their unit (so that the manifest's numbers
// are the simulated ones exactly); integer ranges uniformly over the integers.
//
// Recording k: the classes in order, each `recordings` long (class-major). Its random stream is
// splitmix64 (Steele, Lea & Flood 2014) seeded from hash(seed) ^ (k + 1) * golden ratio: the
// same draws for recording k whatever the number of threads, ranks or recordings generated
// before it. The simulation's own seed (noise, pitch errors, runout phases) is drawn from it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/io/recording.hpp"

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
  // type bearing: a localized defect of a rolling bearing (the scenario's faults[] type bearing,
  // sim::BearingFault); the bearing and its fault drawn among those listed (empty: any bearing
  // of the gearbox at a simulator bearing location; any of outer race, inner race, ball).
  std::vector<std::string> bearings, bearing_faults;
  Range amplitude{0, 0};           // amplitude_m_per_s2: one impact's ring at full load
  Range resonance_hz{3000, 3000};  // the ring's frequency [Hz]
};

// A sporadic tooth defect of a kinematic class (seed 003; dataset_modes.cpp): on a power-path
// gear, its size in the gear's own rotation or at the output, where it enters the mesh.
struct KinematicDefect {
  std::string type = "chip";       // kept in the truth
  std::vector<std::string> gears;  // empty: any power-path gear
  bool size_at_output = false;     // size_output_deg given instead of size_deg
  Range size_deg;
  bool any_phase = true;
  Range phase_deg;
};

// The drawn parameters of a face-gear pair (seed 002), each a number or [lo, hi].
struct FaceGearRanges {
  Range speed_rpm, torque_nm;
  bool has_backlash = false;
  Range backlash_um;
  Range stiffness_scale{1, 1}, static_te_scale{1, 1};
  bool has_fluctuation = false;  // else the description's torque_fluctuation stands
  Range input_amplitude{0, 0}, input_frequency_hz{0, 0}, load_amplitude{0, 0},
      load_frequency_hz{0, 0};
};

struct DatasetClass {
  std::string name;
  int recordings = 0;
  std::vector<DatasetFault> faults;
  std::vector<KinematicDefect> defects;  // kinematic datasets
  FaceGearRanges face_gear;              // face-gear datasets: the spec's, overridden per class
};

// A set of sensors (dynamic datasets): the channels a recording keeps, as names or glob patterns
// of the simulator's channel names (`geardiag info` lists them), and its tachometers (all when
// `tachos` is not given). One set is drawn per recording.
struct SensorSet {
  std::string name;
  std::vector<std::string> channels, tachos;
  bool all_tachos = true;
};

// The kinematic simulator's settings (sim::KinematicOptions), amplitudes at the output shaft.
struct KinematicSettings {
  double step_deg = 0;     // 0: per recording, 1/24 of the smallest defect pulse, <= 0.001 rad
  double revolutions = 0;  // input revolutions; 0: six periods of the slowest path shaft
  Range runout_deg{0, 0}, mesh_te_deg{0, 0}, noise_deg{0, 0};
  std::int64_t encoder_counts = 0;
};

// A machine's life (`life` in a dynamic spec; tools/dataset_life.hpp): every class's
// `recordings` are histories of `recordings` dated recordings each.
struct LifeSettings {
  int recordings = 0;  // per history, >= 2
  int reference = 0;   // healthy recordings at the start of every history, [1, recordings - 1]
  IntRange onset;      // the step the fault starts at, within [reference, recordings - 1]
  std::string start;   // the first recording's time, "YYYY-MM-DDTHH:MM:SS"
  double interval_h = 24;
  double speed_jitter = 0, torque_jitter = 0;  // relative, drawn uniformly in +-jitter
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
  // The simulator: "dynamic" (default), "kinematic" (seed 003: shaft angles with sporadic
  // defects) or "face_gear" (seed 002: the face-gear pair; gearbox_json holds its descriptions
  // and gearbox_files their resolved paths); simulator_of (dataset_simulator.hpp) gives its
  // DatasetSimulator.
  std::string simulator = "dynamic";
  KinematicSettings kinematic;
  std::vector<nlohmann::json> gearbox_json;
  std::vector<std::filesystem::path> gearbox_files;
  std::vector<std::string> warnings;   // printed by the command (e.g. too few revolutions)
  std::vector<SensorSet> sensor_sets;  // empty: every channel the simulator writes
  std::optional<LifeSettings> life;    // life histories (dynamic datasets)
  bool bearing_faults = false;         // a class has a bearing fault: the manifest's columns
};

struct DrawnFault {
  std::string type, gear, shaft;
  int tooth = 0;
  double size_mm = 0, depth_um = 0, position_mm = 0, width_fraction = 1;
  bool has_depth = false, has_position = false;
  std::string bearing, bearing_fault;  // type bearing: where, and outer_race / inner_race / ...
  double amplitude = 0, resonance_hz = 0;
};

struct DrawnDefect {
  std::string type, gear, shaft;
  double size_gear_deg = 0, size_output_deg = 0, phase_deg = 0, period_input_rev = 0,
         first_event_input_deg = 0;
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
  nlohmann::json scenario;  // the scenario simulated (docs/formats.md)
  // Kinematic: the defects and settings; face gear: the drawn pair parameters. `model` is the
  // description simulated (the gearbox with its defects, or the face-gear pair's).
  std::vector<DrawnDefect> defects;
  double step_rad = 0, revolutions = 0, runout_deg = 0, mesh_te_deg = 0, kin_noise_deg = 0;
  double backlash_um = 0, stiffness_scale = 1, static_te_scale = 1, input_amplitude = 0,
         input_frequency_hz = 0, load_amplitude = 0, load_frequency_hz = 0;
  nlohmann::json model;
  int sensor_set = -1;  // index into DatasetSpec::sensor_sets, -1: none
  // A life history's recording: the history, its step in it, the step the fault starts at (-1:
  // a healthy life), its time, and the sensor noise's own seed (`seed` is the gears').
  int history = -1, step = -1, onset = -1;
  std::string time;
  std::uint64_t noise_seed = 0;
};

// The random stream of one recording (splitmix64, Steele, Lea & Flood 2014), and the draws made
// from it. Every draw consumes exactly one number, fixed values included, so that changing one
// field from a value to a range leaves the other fields' draws as they were.
class DrawStream {
 public:
  DrawStream(std::uint64_t seed, std::size_t k) {
    std::uint64_t s = seed;
    state_ = splitmix64(s) ^ ((static_cast<std::uint64_t>(k) + 1) * 0xd1b54a32d192ed03ULL);
  }
  double uniform() { return static_cast<double>(splitmix64(state_) >> 11) * 0x1.0p-53; }
  // Uniform in [lo, hi], rounded to 1e-4 of the unit.
  double draw(const Range& r) {
    const double u = uniform();
    if (r.lo == r.hi) return r.lo;
    const double x = std::round((r.lo + u * (r.hi - r.lo)) * 1e4) / 1e4;
    return std::clamp(x, r.lo, r.hi);
  }
  int draw(const IntRange& r) {
    const double u = uniform();
    const int n = r.hi - r.lo + 1;
    return r.lo + std::min(n - 1, static_cast<int>(u * n));
  }
  std::size_t pick(std::size_t n) {
    return std::min(n - 1, static_cast<std::size_t>(uniform() * n));
  }
  std::uint64_t next() { return splitmix64(state_); }

 private:
  static std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
};

// Field parsers shared by the simulators' specs (dataset_spec.cpp; dataset_modes.cpp): a number
// or [lo, hi] within [min, max] (> min when open_min); an integer or integer range; a class name
// (letters, digits, '_', '-'); the `gearbox` path or array of paths; a 16-hex-digit FNV-1a hash.
Range parse_range(const diag::Fields& f, const std::string& key, double min, double max,
                  bool open_min);
IntRange parse_int_range(const diag::Fields& f, const std::string& key, int min, int max);
std::string class_name(const diag::Fields& f);
std::vector<std::string> parse_gearbox_paths(const diag::Fields& f);
// Field `key` as a name, a non-empty array of names or "any" (returned empty), refused naming
// the field otherwise; `what` names one in the messages ("gear name").
std::vector<std::string> names_or_any(const diag::Fields& f, const char* key, const char* what);
std::string fnv1a64_hex(const std::string& text);
// "key[i]", the path of an array element in errors.
std::string indexed(const std::string& key, std::size_t i);

// The spec's `classes` (every simulator's): a non-empty array of objects holding `name` (unique,
// class_name), `recordings` (>= 0, default `per_class`) and the simulator's own `fields`, which
// `parse_fields` reads into the class. Appends to s.classes and counts s.total and s.max_faults
// (the most faults or defects of one class); refuses a spec with no recording or more than 1e8.
void parse_classes(const diag::Fields& f, int per_class, const std::set<std::string>& fields,
                   DatasetSpec& s,
                   const std::function<void(const diag::Fields&, DatasetClass&)>& parse_fields);

// Reads and checks a spec. Throws diag::InputError naming the file and field: unknown fields,
// bad values, a fault on a gear no gearbox has, a tooth beyond a gear's teeth, a fault size the
// tooth cannot take, a sampling rate below 2.5 x the highest mesh harmonic the detectors examine
// (detect::SidebandOptions::mesh_harmonics) at the highest speed.
DatasetSpec load_dataset_spec(const std::filesystem::path& file);

DrawnRecording draw_recording(const DatasetSpec& spec, std::size_t k);

// Keeps the channels and tachometers of the recording's sensor set (nothing when it has none).
void apply_sensor_set(const DatasetSpec& spec, const DrawnRecording& r, diag::Recording& rec);

// The manifest's columns, in order, and one recording's row (flat: one value per column, null
// where a column does not apply).
std::vector<std::string> manifest_columns(const DatasetSpec& spec);
nlohmann::json manifest_row(const DatasetSpec& spec, const DrawnRecording& r);

}  // namespace geardiag
