// Datasets of the other simulators (`geardiag dataset` with "simulator": "kinematic" or a
// face-gear pair; tools/dataset_spec.hpp holds the dynamic simulator's and the common parts;
// each is a DatasetSimulator, dataset_simulator.hpp).
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

// The two simulators' DatasetSimulator rows (kinematic_dataset_simulator,
// face_gear_dataset_simulator) are declared in dataset_simulator.hpp.
#include "dataset_simulator.hpp"
