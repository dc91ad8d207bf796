// Kinematics of a multi-shaft gearbox with sporadic tooth defects (seed 003, Antipenko &
// Shambalova 2012; docs/physics.md). Slow rotation, no dynamics: the output shaft's angle as a
// function of the input shaft's angle.
//
// Model. Each mesh on the power path maps its up-side gear's angle to the down-side gear's angle,
// theta_down = theta_up z_up / z_down, less the "deficit" g(.) that defective teeth of either gear
// open in the contact. A defect of size D (an angle of its own gear) passing the mesh opens a gap
// at once; the driven side, held by the load, cannot turn back, so it stops until the driver has
// taken the gap up (the seed's "stop"), then follows with the lag; as the defect leaves the
// contact the gap closes over a recovery span and the driven side catches up with accelerated
// motion. In formulas, per mesh and per step:
//     theta_down[n] = max(theta_down[n-1], theta_up[n] z_up / z_down - g(theta))
// with g = D_down (gap in down-gear angle) while the defect is in contact (a hold span equal to
// the defect's own size, so the stop completes), then falling linearly to 0 over a recovery span
// of the same size. Applied mesh after mesh from the input to the output, the max() makes two
// defects passing at once overlap as in the seed's Fig. 9 (the output stays stopped while either
// gap is taken up), not add.
//
// A defect of size D on gear i shows at the output as D / u_i (u_i the ratio from gear i to the
// output, seed eq. 4) and recurs every T_i = 2 pi u / u_i of input angle (eq. 5, corrected).
//
// Measurement effects (switchable, all off by default): once-per-revolution runout of every shaft
// on the power path and mesh-harmonic transmission error (added to the measured output angle),
// encoder quantisation of both angles, and Gaussian angle noise.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace sim {

struct KinematicOptions {
  double step_rad = 0.001;   // input-angle step [rad], > 0 and < 1/20 of the smallest
                             // defect pulse (checked)
  double revolutions = 0.0;  // input revolutions to simulate; 0: five recurrences of the
                             // longest period on the power path plus one (the seed's rule)
  // Measurement effects, amplitudes in output-shaft angle [rad], >= 0.
  double runout_output_rad = 0.0;   // once-per-revolution runout of every path shaft
  double mesh_te_output_rad = 0.0;  // mesh-frequency TE per mesh (harmonics 1..3 at 1, 1/2, 1/4)
  double noise_output_rad = 0.0;    // Gaussian noise on the output angle, RMS
  double noise_input_rad = 0.0;     // Gaussian noise on the input angle, RMS
  std::int64_t encoder_counts_per_rev = 0;  // quantisation of both encoders; 0: none, else >= 16
  std::uint64_t seed = 1;                   // phases of runout/TE and the noise come from this seed

  void validate() const;  // throws diag::InputError naming the field
};

struct KinematicResult {
  std::vector<double> input_angle_rad;   // measured input angle (unwrapped)
  std::vector<double> output_angle_rad;  // measured output angle (unwrapped, same sense)
  std::vector<double> irregularity_rad;  // delta_phi = phi_in / u - phi_out (measured)
  double step_rad = 0.0;
  nlohmann::json truth;  // defects with periods, sizes at output, first events
};

// Simulates the defects of gb.defects(). Throws diag::InputError for invalid options or a step
// too coarse for the smallest defect.
KinematicResult simulate_kinematic(const diag::Gearbox& gb, const KinematicOptions& options);

// Packs a result into a Recording: signals input_angle_rad, output_angle_rad,
// transmission_error_rad (direction "angle"; fs from the input speed), the gearbox JSON and the
// truth. Samples are uniform in input angle, which is uniform in time at constant speed.
diag::Recording to_recording(const diag::Gearbox& gb, const KinematicResult& r);

}  // namespace sim
