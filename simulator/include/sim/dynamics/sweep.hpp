// Frequency-response sweep (seed 000's Fig. 9: the resonance and its jump differ between run up
// and run down). The input speed ramps slowly and continuously from from_rpm to to_rpm
// (run up) and back (run down); each run is cut into `steps` windows of equal speed span and the
// peak and RMS (about the window mean) of the chosen channels are reported per window, with the
// fraction of time the meshes spent out of contact. Because every window starts from the state
// the previous one left, the nonlinear (contact-loss) resonance shows its jump at different
// speeds up and down.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/dynamics/simulate.hpp"

namespace sim {

inline constexpr int kMaxSweepSteps = 1000;  // windows per run (docs/limits.md)

struct SweepOptions {
  double from_rpm = 0.0;  // [rpm], > 0
  double to_rpm = 0.0;    // [rpm], > from_rpm
  int steps = 40;         // windows per run, [2, kMaxSweepSteps]
  bool down = true;       // also run down
  double dwell_s = 0.0;   // time per window [s]; 0: 200 mesh periods of the first mesh at
                          // from_rpm, at least 0.01 s
  double fs_hz = 0.0;     // output rate [Hz]; 0: 8 x the highest mesh frequency
  std::vector<std::string> channels;  // channels to report; empty: every mesh force and the
                                      // first bearing's along/normal LOA accelerations
  void validate() const;
};

struct SweepPoint {
  double rpm = 0.0;                    // window centre
  double mesh_frequency_hz = 0.0;      // of the first mesh
  std::vector<double> peak;            // per channel: max |x - mean|
  std::vector<double> rms;             // per channel: RMS of x - mean
  double contact_loss_fraction = 0.0;  // share of samples with a mesh out of drive-flank contact
};

struct SweepResult {
  std::vector<std::string> channels;
  std::vector<SweepPoint> up, down;
  std::vector<double> natural_frequencies_hz;
  std::vector<double> mesh_torsional_frequency_hz;  // per mesh
  std::vector<double> resonance_rpm;                // input speed at which mesh 0's frequency
                                                    // meets each torsional frequency
  nlohmann::json to_json() const;
};

SweepResult run_sweep(const diag::Gearbox& gb, const DynamicsOptions& dynamics,
                      const RunOptions& run, const SweepOptions& sweep);

// Half-power (-3 dB bandwidth) estimate of a resonance's damping ratio from a sampled frequency
// response (Ewins, Modal Testing, 2nd ed. 2000, section 4.3): the largest amplitude A_max at f_p,
// the frequencies f1 < f_p < f2 where the amplitude falls to A_max / sqrt(2) (linear
// interpolation between the samples), and zeta = (f2 - f1) / (2 f_p). For a receptance
// 1/|k - m w^2 + i c w| this is zeta (1 + O(zeta^2)) (0.3 % high at zeta = 0.05), provided the
// samples resolve the band (several points within f2 - f1). `frequency_hz` must increase
// strictly, the amplitudes be >= 0; throws diag::InputError (naming the side) when the response
// does not fall below A_max / sqrt(2) on both sides of the peak within the data.
struct HalfPower {
  double peak_hz = 0, f1_hz = 0, f2_hz = 0, damping_ratio = 0;
};
HalfPower half_power_damping(const std::vector<double>& frequency_hz,
                             const std::vector<double>& amplitude);

}  // namespace sim
