// Datasets of the other simulators (`geardiag dataset` with "simulator": "kinematic" or a
// face-gear pair; tools/dataset_spec.hpp holds the dynamic simulator's and the common parts).
//
// Kinematic (seed 003, Antipenko & Shambalova 2012; sim/kinematic/sporadic_defects.hpp): every
// recording is the input and output shaft angles at slow rotation with the class's sporadic
// defects. Spec fields: gearbox (ordinary descriptions without defects[]), seed,
// recordings_per_class, simulator: "kinematic", kinematic {step_deg, revolutions, runout_deg,
// mesh_te_deg, noise_deg, encoder_counts}, classes[] {name, recordings, defects[] {gear, type,
// size_deg | size_output_deg, phase_deg}}. A defect goes on a power-path gear ("any": drawn among
// them); its truth (shaft, size at the gear and at the output, recurrence period T_i = 2 pi u /
// u_i in input revolutions, seed eq. 5 corrected, and the first event) is in the manifest.
//
// Face gear (seed 002, Feng et al.; sim/facegear/face_gear.hpp): selected by a face-gear
// description as `gearbox`. Spec fields: gearbox, seed, recordings_per_class, duration_s, fs_hz,
// operating_points {speed_rpm, torque_nm}, face_gear {backlash_um, stiffness_scale,
// static_te_scale, torque_fluctuation {input_amplitude, input_frequency_hz, load_amplitude,
// load_frequency_hz}}, classes[] {name, recordings, operating_points, face_gear} (a class's
// fields replace the spec's). The recording is `geardiag simulate`'s for the pair (DTE, mesh
// torque, angles, contact state); its outcome (DLF, impact class, period class, DTE peak to peak)
// is read back from each file's truth into the manifest.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dataset_spec.hpp"
#include "diag/io/recording.hpp"

namespace geardiag {

// "dynamic", "kinematic" or "face_gear": the spec's `simulator` field, else "face_gear" when its
// first gearbox is a face-gear description, else "dynamic".
std::string dataset_simulator(const nlohmann::json& spec, const std::filesystem::path& file);

// Parses and checks a kinematic or face-gear spec into s (s.file, s.json and s.simulator set).
// Throws diag::InputError naming the field before anything is written.
void load_mode_spec(DatasetSpec& s);

// Recording k's draws (r.index, id, cls set; rng seeded from (seed, k)).
void draw_mode_recording(const DatasetSpec& s, const DatasetClass& cls, DrawStream& rng,
                         DrawnRecording& r);

std::vector<std::string> mode_manifest_columns(const DatasetSpec& s);
nlohmann::json mode_manifest_row(const DatasetSpec& s, const DrawnRecording& r);

// Simulates one drawn recording (its /truth is the simulator's).
diag::Recording simulate_mode_recording(const DatasetSpec& s, const DrawnRecording& r);

// Face gear: the outcome columns from the simulator's truth (dlf, impact, period,
// dte_peak_to_peak_urad) into a manifest row; nothing for the other simulators.
void add_mode_outcomes(const DatasetSpec& s, const nlohmann::json& truth, nlohmann::json& row);

}  // namespace geardiag
