// A dynamic run: the gearbox model integrated over time, sensors sampled at the user's rate.
//
// Integration. Fixed-step RK4 (default) with the step h = 1 / (fs D): D >= 4 internal steps per
// output sample, and enough that h resolves the highest natural frequency (steps_per_period steps
// per period) and the highest mesh frequency (steps_per_mesh per mesh period). A user step larger
// than the RK4 stability bound (h w_max > 2) is reduced and the reduction is reported in
// warnings. The adaptive Runge-Kutta-Prince-Dormand (8,9) of GSL odeiv2 is offered to verify the
// fixed step: it is stepped to the same internal sample times.
//
// Output. Every channel is computed at the internal rate and low-pass filtered and decimated by
// D (diag::Decimator: flat to 0.8 of the output Nyquist frequency, stopband from the output
// Nyquist frequency), so nothing aliases; contact states and tachometer pulses are sampled, not
// filtered. The run starts from the static equilibrium and the first settle_s seconds are
// discarded.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"
#include "sim/bearing/bearing_signal.hpp"
#include "sim/dynamics/gearbox_model.hpp"

namespace sim {

// Documented upper bounds of a dynamic run (docs/limits.md), checked before it starts.
inline constexpr double kMaxDurationS = 3600.0;              // recorded duration [s]
inline constexpr double kMaxFsHz = 1e6;                      // output sampling rate [Hz]
inline constexpr double kMaxSettleS = 600.0;                 // discarded transient [s]
inline constexpr int kMaxStepsPerPeriod = 10000;             // steps_per_period, steps_per_mesh
inline constexpr int kMaxContactSubsteps = 256;              // contact_substeps
inline constexpr double kMaxStepsPerSample = 1e6;            // integration steps per output sample
inline constexpr double kMaxRunSteps = 2e9;                  // integration steps x meshes per run
inline constexpr double kMaxOutputBytes = 4.0 * (1u << 30);  // samples x channels x 8 bytes

// The simulator's accelerometer locations: two bearings per shaft, "<shaft>_bearing1" and
// "<shaft>_bearing2" (index 1 or 2); every bearing channel's `location` is one of them.
std::string bearing_location(const std::string& shaft, int index);
// Whether a bearing of a gearbox description is named as one of its shaft's locations (where a
// bearing defect's impacts can be recorded).
bool at_bearing_location(const diag::BearingSpec& bearing);

// A localized rolling-bearing defect (scenario faults[] type "bearing"): the impacts of
// sim/bearing/bearing_signal.hpp's model at the bearing's shaft speed, added to every
// accelerometer at the bearing (the channels whose location is its name: the simulator's
// "<shaft>_bearing1" and "<shaft>_bearing2"). The impacts ring the sensor's own structural
// resonance and are not fed back into the gears' dynamics: a spall's excitation of the shafts is
// small beside the meshes', and what a diagnosis sees of it is the ring at the sensor.
struct BearingFault {
  std::string bearing;  // a bearing of the gearbox description, with its geometry
  BearingFaultKind kind = BearingFaultKind::kOuterRace;  // outer race, inner race, ball or cage
  double amplitude_m_per_s2 = 0;  // one impact's ring at its peak, at full load [m/s^2], > 0
  double resonance_hz = 3000;     // the ring's frequency [Hz], < 0.45 fs
  double damping_ratio = 0.05;    // (0, 0.5]
  double mean_slip = 0.01;        // contact rates (1 - slip) x kinematic, [-0.05, 0.05]
  double jitter = 0.01;           // relative RMS fluctuation of each interval, [0, 0.1]
  std::string where;  // where it was described ("s.json: faults[2]"), for errors; "" from code
};

struct RunOptions {
  double duration_s = 1.0;  // recorded duration [s], > 0
  double fs_hz = 20000.0;   // output sampling rate [Hz], > 0
  double settle_s = -1.0;   // discarded transient [s]; < 0: automatic (ten time constants of
                            // the least damped mode, at least 0.05 s)
  enum class Method { kRk4, kGslRk8pd } method = Method::kRk4;
  double step_s = 0.0;        // RK4 step [s]; 0: automatic
  int steps_per_period = 20;  // RK4 steps per period of the highest natural frequency, >= 8
  int steps_per_mesh = 48;    // RK4 steps per period of the highest mesh frequency, >= 8
  // RK4 steps across which a tooth pair enters or leaves a mesh (GearboxModel::
  // contact_signature) are redone as this many sub-steps, >= 1 (1: off). Why: the pair stiffness
  // jumps there, RK4 is only first order across the jump, and its error depends on where in the
  // step the jump falls; with a step incommensurate with the mesh period that position cycles
  // with the beat between the two and leaves spurious periodic content (the two-stage box at
  // 2000 rpm and a 5 us step: lines at every 3rd input-shaft order, 3.6 % of the vibration RMS,
  // enough to look like a damaged input gear to time-synchronous averaging). 32 sub-steps cut it
  // by about 32 (first order) at about +25 % run time (four such steps per mesh period).
  int contact_substeps = 32;
  double gsl_rel_tol = 1e-9;  // GSL odeiv2 relative / absolute tolerance
  double gsl_abs_tol = 1e-13;
  double accel_noise_m_per_s2 = 0.0;   // accelerometer noise, Gaussian, RMS [m/s^2], >= 0
  double casing_frequency_hz = 0.0;    // casing transmission path resonance [Hz]; 0: none
  double casing_damping_ratio = 0.05;  // its damping ratio, (0, 1)
  std::uint64_t seed = 1;              // sensor noise
  bool mesh_channels = true;           // dynamic mesh force, friction, DTE, contact per mesh
  bool bearing_channels = true;        // accelerations at every bearing
  // Bearing defects: their impacts on the accelerometers at the bearing (needs a constant speed
  // and the bearing's channels); the impacts' randomness is seeded from `seed` and the index.
  std::vector<BearingFault> bearing_faults;
  void validate() const;  // throws diag::InputError naming the field
};

// A channel at the output rate (fs_hz = DynamicResult::fs_hz), as a recording holds it.
using Channel = diag::Signal;

struct DynamicResult {
  double fs_hz = 0.0;
  std::vector<Channel> channels;
  std::vector<Channel> tachos;        // 0/1 pulse trains, once per revolution, per shaft
  double step_s = 0.0;                // the integrator's step (RK4) or sample spacing (GSL)
  int decimation = 1;                 // internal samples per output sample
  std::vector<std::string> warnings;  // said on stderr by the CLI
  nlohmann::json truth;               // operating point, model, faults, natural frequencies
  const Channel* find(const std::string& name) const;
};

// Throws diag::InputError for bad options and when the integration diverges (non-finite state or
// a mesh deflection beyond 1000 static deflections), naming the time and what to change.
DynamicResult simulate_dynamic(const diag::Gearbox& gb, const DynamicsOptions& dynamics,
                               const RunOptions& run);

// Packs a result into a Recording (signals, tachos, the gearbox JSON, the truth).
diag::Recording to_recording(const diag::Gearbox& gb, const DynamicResult& r);

}  // namespace sim
