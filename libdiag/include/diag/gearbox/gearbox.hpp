// A gearbox: shafts, gears on shafts, meshes (driver -> driven), bearings, the input operating
// point and, for the simulator, defects. Everything derived from the topology lives here, in one
// place: shaft speeds and ratios, mesh frequencies, each gear's defect recurrence period (seed
// 003, corrected formula: docs/physics.md), hunting-tooth periods, which gears share a shaft.
//
// The JSON form is documented in docs/formats.md ("Gearbox description"); parse_gearbox() refuses
// bad descriptions with an InputError naming the field and the reason.
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diag/geometry/gear.hpp"
#include "diag/geometry/gear_pair.hpp"

namespace diag {

// Documented upper bounds of a description (docs/limits.md); beyond them parse_gearbox refuses
// with the field named, before any derived quantity is computed.
inline constexpr int kMaxTeeth = 1000;
inline constexpr double kMinModuleMm = 0.05, kMaxModuleMm = 100.0;
inline constexpr double kMaxSpeedRpm = 1e5;           // input shaft [rpm]
inline constexpr double kMaxTorqueNm = 1e7;           // input torque [N m]
inline constexpr std::size_t kMaxGearboxItems = 256;  // shafts, gears, meshes, bearings, defects

struct GearEntry {
  std::string name;
  std::string shaft;
  GearSpec spec;
};

struct MeshSpec {
  std::string driver;              // gear name
  std::string driven;              // gear name
  double backlash_m = 0.0;         // circumferential backlash along the LOA [m], >= 0
  double centre_distance_m = 0.0;  // 0: the zero-backlash working distance from the profile shifts
};

struct InputSpec {
  std::string shaft;
  double speed_rpm = 0.0;  // input shaft speed [rpm], > 0
  double torque_nm = 0.0;  // input torque [N m], >= 0
};

struct BearingSpec {
  std::string name;
  std::string shaft;
  int rolling_elements = 0;         // n, >= 3
  double pitch_diameter_m = 0.0;    // P_d [m], > 0
  double element_diameter_m = 0.0;  // B_d [m], 0 < B_d < P_d
  double contact_angle_rad = 0.0;   // phi [rad], [0, pi/2)
};

// A sporadic tooth defect (seed 003, docs/physics.md): an angular loss of the gear's own rotation
// that appears once per revolution of the gear.
struct DefectSpec {
  std::string gear;
  std::string type = "chip";  // chip | breakage | pit | crack | missing (free text kept in truth)
  double size_rad = 0.0;      // loss in the gear's own rotation [rad], > 0
  double phase_rad = 0.0;     // gear's own angle at which the defect enters the mesh, [0, 2 pi)
  int tooth = -1;             // tooth index when given as a tooth (phase = tooth * 2 pi / z)
};

struct Shaft {
  std::string name;
  double speed_ratio = 0.0;  // omega_shaft / omega_input, signed (negative: opposite sense)
  std::vector<int> gears;    // indices into Gearbox::gears()
};

// One mesh on the kinematic path from the input shaft to the output shaft, oriented from the
// input side ("up") to the output side ("down"), which need not be the mesh's driver/driven.
struct PathStep {
  int mesh = -1;
  int up_gear = -1;    // gear on the shaft nearer the input
  int down_gear = -1;  // gear on the shaft nearer the output
};

struct Mesh {
  int driver = -1, driven = -1;  // gear indices
  MeshSpec spec;
  GearPair pair;
};

class Gearbox {
 public:
  const std::string& name() const { return name_; }
  const std::vector<Shaft>& shafts() const { return shafts_; }
  const std::vector<GearEntry>& gears() const { return gears_; }
  const std::vector<Mesh>& meshes() const { return meshes_; }
  const std::vector<BearingSpec>& bearings() const { return bearings_; }
  const std::vector<DefectSpec>& defects() const { return defects_; }
  const InputSpec& input() const { return input_; }
  int input_shaft() const { return input_shaft_; }
  int output_shaft() const { return output_shaft_; }

  int shaft_index(const std::string& name) const;  // -1 when unknown
  int gear_index(const std::string& name) const;   // -1 when unknown
  int shaft_of_gear(int gear) const;

  // |omega_input / omega_output|: the overall ratio u (the seed's u_max for the engaged train).
  double total_ratio() const;
  // u_i = |omega_gear / omega_output|: the ratio from a gear to the output shaft (seed 003, eq. 4).
  double ratio_to_output(int gear) const;
  double shaft_speed_hz(int shaft) const;  // |rotation frequency| [Hz]
  double shaft_speed_rpm(int shaft) const;
  double mesh_frequency_hz(int mesh) const;  // z_driver * f_driver shaft [Hz]
  // Defect recurrence period in input-shaft revolutions: T = |omega_in / omega_shaft| for the shaft
  // carrying the gear. Seed 003 eq. (5) corrected: T_i = 2 pi u_max / u_i (docs/physics.md).
  double recurrence_period_input_rev(int gear) const;
  double shaft_period_input_rev(int shaft) const;
  // Hunting-tooth period of a mesh: the same pair of teeth meets again after lcm(z1, z2) tooth
  // engagements, i.e. z_driven / gcd(z_driver, z_driven) revolutions of the driver; returned in
  // input revolutions: (z_driven / gcd) * the driver shaft's period.
  double hunting_period_input_rev(int mesh) const;
  // The meshes that carry motion from the input shaft to the output shaft, in order (empty when
  // input and output are one shaft). Only defects on these meshes' gears reach the output angle.
  const std::vector<PathStep>& power_path() const { return path_; }
  bool on_power_path(int gear) const;
  // Gears that share a shaft with `gear`, itself included.
  std::vector<int> gears_sharing_shaft(int gear) const;

  // The same gearbox turning at another input speed [rpm] (a measured or recorded speed in
  // place of the description's nominal one). Throws InputError unless finite and > 0.
  Gearbox with_input_speed_rpm(double speed_rpm) const;

  // What the description allows but the user should know (undercut, a shortened contact, a thin
  // tip land), each naming the source and the field. Tools print them to stderr and put them in
  // their JSON output.
  const std::vector<std::string>& warnings() const { return warnings_; }

  // The description as given (JSON text), stored with recordings.
  const std::string& description_json() const { return json_text_; }

  friend Gearbox parse_gearbox(const nlohmann::json& j, const std::string& where);

 private:
  std::string name_;
  std::vector<Shaft> shafts_;
  std::vector<GearEntry> gears_;
  std::vector<Mesh> meshes_;
  std::vector<BearingSpec> bearings_;
  std::vector<DefectSpec> defects_;
  InputSpec input_;
  int input_shaft_ = -1, output_shaft_ = -1;
  std::vector<PathStep> path_;
  std::string json_text_;
  std::vector<std::string> warnings_;
};

// Parses and validates a description. `where` names the source (a file path) in error messages.
Gearbox parse_gearbox(const nlohmann::json& j, const std::string& where);
Gearbox parse_gearbox_text(const std::string& json_text, const std::string& where);
Gearbox load_gearbox(const std::filesystem::path& path);

// A readable multi-line summary: shafts with speeds and ratios, meshes with frequencies and
// contact ratios, gears with recurrence periods, hunting-tooth periods, bearings, defects.
std::string format_summary(const Gearbox& gb);
// The same derived quantities as JSON (keys carry units).
nlohmann::json summary_json(const Gearbox& gb);

}  // namespace diag
