// Once-per-revolution pulse times made fit for time-synchronous averaging at mesh orders: the
// tacho layer's correction of pulse times, shared by every TSA user (the damaged-shaft locator,
// analyze's per-shaft TSA).
//
// 1. Smoothing (smooth_pulse_times_polynomial): a 0/1 pulse train's edges are known only to +- half
// a
//    sampling period (tacho.hpp), which at the high mesh harmonics (kHz) is a phase jitter of
//    tens of degrees per revolution; the TSA turns it into spurious impulsive content. The
//    least-squares polynomial t(k) of the pulse index k (degree 3 by default) replaces the
//    pulses: exact for constant speed and for a linear run-up over a short record, and it
//    averages the jitter over all pulses. Over a long run-up t(k) ~ sqrt(k) is no polynomial
//    (500 -> 3000 rpm over 263 revolutions: a cubic t(k) is off by 5 revolutions), so the
//    polynomial of the same degree for the angle k(t) is fitted as well and inverted at every k
//    when t(k) leaves twice its residual (in time): a linear run-up's angle is exactly quadratic
//    in time. Degree 0: the pulses as detected (use it when the speed wanders: neither fit is a
//    polynomial).
// 2. Phase correction from the vibration (refine_pulses_from_phase; Bonnardot et al. 2005, Mech.
//    Syst. Signal Process. 19, phase demodulation of a mesh line for resampling without a
//    tacho). A regular line of order k is measured in every revolution of the resampled record;
//    its phase there is c + k e_r, e_r the error of the assumed shaft angle in revolution r; the
//    pulses move by -e / (2 pi) of a period (e interpolated between revolution middles) and the
//    record is resampled again (twice). First with the shaft's lowest mesh order (its phase step
//    per revolution, k eps, stays unambiguous up to a speed error of 0.5 / k), then with its
//    strongest regular line (the most precise phase). A stage is kept only when (a) the line's
//    amplitude is steady to 0.1 of its mean over the revolutions (its phase known to ~0.1 rad),
//    (b) no pulse moves by half a period of the line or more (beyond, the phase steps are
//    ambiguous and the angle can lock onto a neighbouring order) and (c) the TSA's regular lines
//    gain energy (they became more coherent). So it corrects small errors only (the tacho's
//    quantisation and the rate error of its fit, ~1e-5); a speed error of 0.5 % over 44
//    revolutions is left as it is and smears the averages: no finding rather than a wrong one.
//    Why it matters: a 0/1 tacho sampled at fs places each pulse late by up to one sampling
//    period, by an amount that follows the fractional part of (revolution x samples per
//    revolution); when that beats slowly (267.48 samples per revolution: period 50 revolutions)
//    the polynomial fit keeps it, and the fit's rate error (~1e-5) adds a phase ramp. At order
//    108 (4 kHz) 50 us is 1.3 rad: a loud mesh line wanders in phase from revolution to
//    revolution, its one-revolution leakage stays in the average coherently, and a healthy shaft
//    looks damaged (the gear-damage loop's false alarms near 2243 rpm before this correction).
// 3. refine_pulses: both, for a gearbox: the reference shaft's pulses are smoothed, scaled to the
//    fastest shaft that carries gears and has a vibration channel, corrected there (the error is
//    the reference pulses', and the fastest shaft sees it at the lowest orders, where a phase step
//    per revolution stays unambiguous longest), and returned as that shaft's pulses: every other
//    shaft's revolutions follow by scale_pulses (resample.hpp) with the speed ratio. Correcting
//    each shaft on its own could leave the slow shafts smeared while a fast one is corrected: a
//    slow shaft's fault, which folds into the faster shafts' averages, would then be put on the
//    fast shaft.
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace detect {

// Step 1. degree in [0, 8] (0 or fewer than degree + 2 pulses: returned as they are). Throws
// diag::InputError for a degree outside [0, 8].
std::vector<double> smooth_pulse_times_polynomial(std::span<const double> pulse_times_s,
                                                  int degree);

struct PhaseRefinement {
  std::vector<double> pulses;  // corrected (the input when no stage was kept)
  std::size_t line = 0;        // the last order followed that was kept; 0: pulses unchanged
};
// Step 2 on one channel: pulses once per revolution of the shaft whose regular orders (a mask
// over 0 .. samples_per_rev / 2, tsa_regular_orders) are given; first_line the shaft's lowest
// mesh order (0: only the strongest regular line). Throws diag::InputError when the record
// cannot be resampled (fewer than min_revolutions whole revolutions).
PhaseRefinement refine_pulses_from_phase(const diag::Signal& channel,
                                         std::span<const double> pulse_times_s, int samples_per_rev,
                                         const std::vector<bool>& regular, std::size_t first_line,
                                         int min_revolutions);

// Every mesh frequency of the gearbox that is an integer order of `shaft` (its |speed_ratio|
// divides the mesh frequency exactly, to round-off), up to max_order, each once.
std::vector<int> synchronous_mesh_orders(const diag::Gearbox& gb, const diag::Shaft& shaft,
                                         int max_order);

// The vibration channels that see a shaft, by the channel contract (diag::shaft_sensors: the
// channel's shaft, or a location naming a bearing of the shaft): the first location only (two
// bearings of one shaft see the same rigid shaft motion), along each line of action when there
// are such; without sensors on the shaft, every sensor channel (a casing sensor serves all
// shafts).
std::vector<const diag::Signal*> shaft_vibration_channels(const diag::Recording& rec,
                                                          const diag::Gearbox& gb,
                                                          const std::string& shaft);

// TSA resolution for a shaft turning at shaft_hz in a record sampled at fs_hz: orders up to
// band_fraction x (fs / 2) / shaft_hz are analysed; samples_per_rev 0: the smallest power of two
// >= 2.8 x that order (the resampling filter passes 0.72 of the Nyquist order, resample.hpp),
// clamped to [64, 16384]; `top` the highest order analysed (within the passband).
struct TsaResolution {
  int samples_per_rev = 0;
  std::size_t top = 0;
};
TsaResolution tsa_resolution(double fs_hz, double shaft_hz, double band_fraction,
                             int samples_per_rev = 0);

struct PulseRefineOptions {
  int pulse_fit_degree = 3;      // step 1, [0, 8]
  bool phase_correction = true;  // step 2
  double band_fraction = 0.8;    // tsa_resolution, (0, 1]
  int samples_per_rev = 0;       // tsa_resolution: 0 automatic, else a power of two >= 64
  int min_revolutions = 8;       // >= 2
  // shaft -> channels to use for the phase (overrides shaft_vibration_channels)
  std::map<std::string, std::vector<std::string>> channels;

  void validate() const;  // throws diag::InputError naming the field
};

struct RefinedPulses {
  std::string shaft;           // the shaft the pulses are once per revolution of
  std::vector<double> pulses;  // corrected times [s]
  std::size_t line = 0;        // order of `shaft` whose phase corrected them; 0: smoothed only
  std::string channel;         // the channel that gave the phase ("" when line == 0)
  std::string note;            // what was done, for the user
};
// Step 3: pulse_times_s once per revolution of reference_shaft. Without a phase correction the
// result is reference_shaft's smoothed pulses. Throws diag::InputError for bad options, an
// unknown shaft, fewer than 3 pulses, or pulses that are not finite and strictly increasing.
RefinedPulses refine_pulses(const diag::Recording& rec, const diag::Gearbox& gb,
                            const std::string& reference_shaft,
                            std::span<const double> pulse_times_s,
                            const PulseRefineOptions& options = {});

}  // namespace detect
