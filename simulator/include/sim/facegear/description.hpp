// The face-gear pair in a gearbox description (its own pair type, key "face_gear_pair"), the
// stiffness tables from a CSV file, and the analytical default tables for the seed's pair.
//
// JSON (every field but pinion/gear teeth optional; units in the key names):
//   {"name": "...",
//    "face_gear_pair": {"pinion_teeth": 15, "gear_teeth": 121, "normal_module_mm": 2.75,
//        "normal_pressure_angle_deg": 27.5, "helix_angle_deg": 15, "gear_inner_diameter_mm":
//        160.52, "gear_outer_diameter_mm": 190.04, "pinion_face_width_mm": 34.52,
//        "gear_face_width_mm": 29.52, "pinion_inertia_kg_m2": ..., "gear_inertia_kg_m2": ...,
//        "backlash_um": 50, "mesh_damping_ratio": 0.05 | "damping_alpha": a, "damping_beta": b,
//        "bearing_damping_nms": [c_p, c_g], "stiffness_table": "file.csv" | "analytic",
//        "stiffness_scale": 1, "static_te_um": [drive, coast]},
//    "input": {"speed_rpm": 4000, "torque_nm": 300},
//    "torque_fluctuation": {"input_amplitude": a, "input_frequency_hz": f_p, "input_phase_deg":,
//                           "load_amplitude": b, "load_frequency_hz": f_g, "load_phase_deg":}}
// A relative stiffness_table path is taken relative to the description file.
//
// CSV table (header required, any row order):
//   flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad
//   drive,0,1,8.1e5,2.3
// flank is drive or coast; angle_deg the pinion angle in [0, 360/N_p); for each flank every
// (angle, load) pair of its grid once; e0_urad [face-gear micro-rad] the same for every load of
// an angle.
//
// HDF5 table (the same columns as arrays; read with diag::read_hdf5_arrays, so h5py or MATLAB
// write it):
//   /angle_deg                    1-D, n_a: pinion angle in [0, 360/N_p), strictly increasing
//   /load_nm                      1-D, n_l: mesh load [N m, pinion torque], strictly increasing,
//                                 >= 0
//   /drive/stiffness_nm_per_rad   2-D, n_a x n_l (row i: angle i), > 0
//   /drive/e0_urad                1-D, n_a: static TE [face-gear micro-rad]
//   /coast/stiffness_nm_per_rad, /coast/e0_urad   the coast flank, the same shapes
// A flank may have its own grid (/drive/angle_deg, /drive/load_nm), which then shapes its arrays
// instead of the root's. Numbers of any integer or float type; other datasets are ignored.
// Outside the load grid the nearest load's row is used (constant extrapolation, FlankTable).
//
// Analytical default (derivation in docs/face-gear.md): mean torsional stiffness from
// ISO 6336-1's mesh stiffness c_gamma = 20 N/(mm um) times the face width, referred to the
// pinion base radius and the face gear's mean radius; ISO 6336-1's low-load reduction
// (w / 100 N/mm)^0.25 for a line load w < 100 N/mm gives the load dependence; the angle
// dependence is a two-term Fourier series of the mesh period (the alternation of tooth pairs);
// the coast flank is 5 % softer with a different phase; the static TE is one mesh harmonic per
// flank.
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "sim/facegear/face_gear.hpp"

namespace sim::facegear {

struct Geometry {
  int pinion_teeth = 15, gear_teeth = 121;
  double normal_module_m = 2.75e-3;
  double normal_pressure_angle_rad = 27.5 * 3.14159265358979323846 / 180.0;
  double helix_angle_rad = 15.0 * 3.14159265358979323846 / 180.0;
  double gear_inner_diameter_m = 160.52e-3, gear_outer_diameter_m = 190.04e-3;
  double pinion_face_width_m = 34.52e-3, gear_face_width_m = 29.52e-3;

  double pinion_pitch_radius_m() const;  // m_n N_p / (2 cos beta)
  double gear_mean_radius_m() const;     // (L1 + L2) / 4
};

struct Description {
  std::string name = "face-gear pair";
  Geometry geometry;
  FaceGearPair pair;
  Operating operating;
  double mesh_damping_ratio = 0.05;  // used when alpha/beta are not given
  std::string table_source = "analytic";
};

// The analytical default tables for a geometry (per flank: 32 angles x 9 loads 1..400 N m) and
// static TE amplitudes [um at the face gear's mean radius].
void analytic_tables(const Geometry& g, double te_drive_um, double te_coast_um, FlankTable& drive,
                     FlankTable& coast);
// Default inertias: the pinion as a solid steel cylinder of its pitch radius and face width, the
// face gear as a steel ring between its inner and outer radius, 15 mm thick.
double default_pinion_inertia(const Geometry& g);
double default_gear_inertia(const Geometry& g);

// Reads a CSV table file; throws diag::InputError naming the file, line and field.
void load_table_csv(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                    FlankTable& coast);
// Reads an HDF5 table file (layout above); throws diag::InputError naming the file, dataset and
// reason. The same table as CSV gives bit-identical FlankTables.
void load_table_hdf5(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                     FlankTable& coast);
// Either, by the file's content (the HDF5 signature), not its name.
void load_table(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                FlankTable& coast);

// True when the JSON is a face-gear description (has "face_gear_pair").
bool is_face_gear(const nlohmann::json& j);
bool is_face_gear_file(const std::filesystem::path& path);
// Parses and validates; `where` names the file (relative table paths resolve against its folder).
Description parse_description(const nlohmann::json& j, const std::string& where);
Description load_description(const std::filesystem::path& path);

// Scenario for the face gear (bifurcation / simulate): {"stiffness_scale": s, "torque_nm": T,
// "backlash_um": b, "static_te_scale": s} applied to a description; unknown fields refused.
void apply_scenario(Description& d, const nlohmann::json& sc, const std::string& where);

}  // namespace sim::facegear
