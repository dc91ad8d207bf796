// A localized rolling-bearing fault as an accelerometer records it: an impact train from the
// bearing kinematics, each impact ringing a structural resonance, modulated by the load zone, with
// random slip, in noise and (optionally) under shaft-order and gear-mesh interference.
//
// Model (McFadden & Smith, "Model for the vibration produced by a single point defect in a rolling
// element bearing", JSV 96 (1984) 69-82; Antoni & Randall, "A stochastic model for simulation and
// diagnostics of rolling element bearings with localized faults", J. Vib. Acoust. 125 (2003)
// 282-289; Randall & Antoni, "Rolling element bearing diagnostics - a tutorial", MSSP 25 (2011)
// 485-520, sec. 2):
//
//   x(t) = sum_k A_k h(t - t_k) + interference(t) + n(t),
//   h(t) = exp(-zeta w_n t) sin(w_d t) (t >= 0),  w_d = w_n sqrt(1 - zeta^2),
//
// the impact times t_k following the defect's contact rate with a fixed mean slip s (the rate is
// (1 - s) times the kinematic one) and a random fluctuation of every interval,
// t_{k+1} - t_k = T (1 + sigma xi_k), xi_k ~ N(0, 1) (Antoni & Randall's model of slip: a
// cumulative random walk of the phase, which smears the higher envelope harmonics). A_k is the
// impact amplitude times the load the defect carries at t_k, from Stribeck's load distribution
// (Harris, "Rolling Bearing Analysis", eq. 6.20; McFadden & Smith eq. 4) with radial load pointing
// to theta = 0 (6 o'clock):
//
//   q(theta) = [1 - (1 - cos theta) / (2 eps)]^(3/2) where the bracket is > 0, else 0,
//
// eps = load_zone_factor (0.5: the load zone spans +-90 degrees).
//
// Kinematics (stationary outer race, inner race turning with the shaft at f_r; rho = (B_d / P_d)
// cos phi): the cage turns at f_c = f_r (1 - rho) / 2, a ball spins about its own axis at
// f_s = (P_d / (2 B_d)) (1 - rho^2) f_r relative to the cage. The classes:
//  - outer race: a spall fixed at theta_o (default 0, the centre of the load zone, CWRU's
//    "@6"); a ball strikes it every 1 / BPFO, BPFO = n f_c; A_k = A q(theta_o), constant.
//  - inner race: a spall on the inner race at theta(t) = 2 pi f_r t + phi_0; struck every
//    1 / BPFI, BPFI = n (f_r - f_c); A_k = A q(theta(t_k)): modulation at the shaft rate.
//  - rolling element: a spall on one ball, which turns with the cage at theta(t) = 2 pi f_c t +
//    phi_0 and, spinning, strikes the outer race and the inner race once each per spin
//    revolution: impacts every 1 / (2 f_s) alternating outer and inner (CWRU tabulates 2 f_s as
//    "BSF"). A_k = A g q(theta(t_k)), g = 1 at the outer race and inner_strike_gain at the inner
//    (a longer path to the sensor through the ball). The load zone modulates the train at the
//    cage rate f_c. A ball's spin axis also wanders, so the spall is not in the rolling track on
//    every passage (Smith & Randall 2015, sec. 5, why ball faults are hard): on each cage
//    revolution the spall is in the track with probability ball_track_probability, else that
//    revolution's strikes are missed.
//  - cage: a damaged cage pocket knocks and rubs as it passes the load zone: the resonance driven
//    by white noise whose amplitude is A q(2 pi f_c t + phi_0): a cyclostationary signal at the
//    cage rate, no impact train at any race or ball rate.
//  - none: interference and noise only.
//
// Noise: white Gaussian, RMS set by snr_db against the fault component's mean power over the
// record (P_fault / P_noise = 10^(snr_db / 10)). For kNone the reference power is that of an
// unmodulated impact train of amplitude A at the BPFO rate, A^2 BPFO / (4 zeta w_n) (the energy
// of h is 1 / (4 zeta w_n) for small zeta), so that a healthy case carries the noise a fault of
// that size would be buried in.
//
// Interference (absolute amplitudes, the unit of A): shaft orders 1..5 with amplitude
// shaft_amplitude / h, and a gear-mesh tone at mesh_hz with harmonics 1..3 (amplitude
// mesh_amplitude / h), amplitude-modulated at the shaft rate with index 0.3.
//
// Deterministic: the same options and seed give the same samples.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "diag/faults/fault_kind.hpp"
#include "diag/gearbox/bearing_rates.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace sim {

enum class BearingFaultKind {
  kNone,            // healthy: interference and noise only
  kOuterRace,       // spall on the stationary outer race
  kInnerRace,       // spall on the rotating inner race
  kRollingElement,  // spall on one ball
  kCage,            // damaged cage pocket
};
// The fault vocabulary's kind and name (diag/faults/fault_kind.hpp): "none", "outer_race",
// "inner_race", "rolling_element", "cage", as the detectors' findings name them.
diag::FaultKind fault_kind(BearingFaultKind k);
const char* to_string(BearingFaultKind k);
// The fault of a name of the vocabulary or one of its aliases ("ball", "roller"); nullopt for a
// name that is not a bearing fault ("none" included).
std::optional<BearingFaultKind> bearing_fault_kind(std::string_view name);

// The contact rates of the model above [Hz]: diag::bearing_rates (FTF, BPFO, BPFI, BSF, 2 BSF),
// the implementation the detectors use too.
using BearingRates = diag::BearingRates;

struct BearingSignalOptions {
  double fs_hz = 12000.0;   // sampling rate [Hz], finite, > 0 (and > resonance_hz / 0.45)
  double duration_s = 5.0;  // record length [s], (0, 600]
  double shaft_hz = 30.0;   // inner-race rotation f_r [Hz], > 0
  BearingFaultKind fault = BearingFaultKind::kOuterRace;
  double impact_amplitude = 1.0;   // A: peak of one impact's ring at full load, the fault's
                                   // "size" [unit of the signal], > 0
  double snr_db = 0.0;             // fault power over noise power [dB], [-60, 60]; see above
  double resonance_hz = 3000.0;    // structural resonance the impacts ring [Hz], (0, 0.45 fs)
  double damping_ratio = 0.05;     // zeta, (0, 0.5]
  double mean_slip = 0.01;         // s: contact rates are (1 - s) x kinematic, [-0.05, 0.05]
  double jitter = 0.01;            // sigma: relative RMS fluctuation of each interval, [0, 0.1]
  double load_zone_factor = 0.5;   // eps of Stribeck's distribution, (0, 1]; >= 1 loads every
                                   // angle
  double defect_angle_rad = 0.0;   // outer race: theta_o of the spall (0: load-zone centre)
  double inner_strike_gain = 0.5;  // ball: inner-race strike relative to outer, [0, 1]
  double ball_track_probability = 1.0;  // ball: share of cage revolutions on which the spall
                                        // is in the track, [0, 1]
  double shaft_amplitude = 0.0;         // shaft-order interference [unit], >= 0
  double mesh_hz = 0.0;                 // gear-mesh frequency [Hz], >= 0 (0: none)
  double mesh_amplitude = 0.0;          // [unit], >= 0
  std::uint64_t seed = 1;               // phases, jitter, track misses and noise

  void validate() const;  // throws diag::InputError "bearing signal: <field>: ..."
};

struct BearingSignal {
  diag::Signal signal;   // "acc", role vibration, unit "m/s^2", location = bearing name
  BearingRates rates;    // kinematic rates at opt.shaft_hz (before slip)
  int impacts = 0;       // impacts generated (0 for kNone and kCage)
  double fault_rms = 0;  // RMS of the fault component
  double noise_rms = 0;  // RMS of the added noise (set from snr_db)
  nlohmann::json truth;  // diag::SimulationTruth's JSON: kind "bearing", the defect (none
                         // when healthy); extra: "bearing", "rates", "impacts", "fault_rms",
                         // "noise_rms", options
};

// Throws diag::InputError for invalid options or geometry.
BearingSignal simulate_bearing_signal(const diag::BearingSpec& bearing,
                                      const BearingSignalOptions& options);

// The fault component of the model above alone: the impact train (or the cage's rub), no noise
// and no interference; `impacts` receives the number of impacts. What a dynamic run adds to the
// accelerometers at a bearing with a defect (sim/dynamics/simulate.hpp, RunOptions::
// bearing_faults). Throws diag::InputError for invalid options or geometry.
std::vector<double> bearing_fault_samples(const diag::BearingSpec& bearing,
                                          const BearingSignalOptions& options, int& impacts);

}  // namespace sim
